"""fictus from Python: the same numbers as the CLI, callables = expressions, bad input raises."""
import csv
import json
import os
import subprocess
import threading
import time

import numpy as np
import pytest

import fictus

EXE = os.environ.get("FICTUS_EXE", "fictus")
EXAMPLES = os.environ.get("FICTUS_EXAMPLES", os.path.join(os.path.dirname(__file__), "..", "..", "examples"))


def cli_solve(tmp_path, *args):
    out = tmp_path / "cli"
    subprocess.run([EXE, "solve", *args, "--out", str(out)], check=True, capture_output=True)
    with open(out / "results.json") as handle:
        results = json.load(handle)
    with open(out / "points.csv") as handle:
        points = list(csv.DictReader(handle))
    return results, points


def test_paper_problem_matches_the_cli(tmp_path):
    results, points = cli_solve(tmp_path, "--N", "128", "--variant", "nonsmooth")
    s = fictus.Problem.paper(N=128, variant="nonsmooth").solve()
    assert s.iterations == results["newton"]["iterations"]
    assert int(s.contact.sum()) == results["newton"]["n_active"]
    for key, value in results["errors"].items():
        assert s.errors[key] == pytest.approx(value, rel=1e-12), key
    lam = np.array([float(p["lambda"]) for p in points])
    np.testing.assert_allclose(s.lambda_, lam, rtol=1e-13, atol=1e-15)
    assert s.options["variant"] == "nonsmooth" and s.options["N"] == 128


def test_problem_file_text_matches_the_cli(tmp_path):
    path = os.path.join(EXAMPLES, "circle.toml")
    results, _ = cli_solve(tmp_path, path, "--N", "128")
    with open(path) as handle:
        problem = fictus.Problem.from_toml(handle.read().replace("N = 256", "N = 128"))
    s = problem.solve()
    assert s.errors["rel_l2_omega"] == pytest.approx(results["errors"]["rel_l2_omega"], rel=1e-12)


CIRCLE = {
    "domain": {"N": 128},
    "geometry": {"shape": "circle", "center": [0.5, 0.5], "radius": 0.3},
    "formulation": {"variant": "smooth"},
}


def test_callables_and_expressions_agree():
    expressions = dict(CIRCLE, data={
        "exact": "max(0, x - 0.5)^3",
        "f": "-6 * max(0, x - 0.5) + max(0, x - 0.5)^3",
        "g": "max(0, x - 0.5)^3 - 0.1 * max(0, 0.5 - x)",
    })
    pos = lambda v: np.maximum(v, 0.0)  # noqa: E731
    callables = dict(CIRCLE, data={
        "exact": lambda x, y: pos(x - 0.5) ** 3,
        "f": lambda x, y: -6 * pos(x - 0.5) + pos(x - 0.5) ** 3,
        "g": lambda x, y: pos(x - 0.5) ** 3 - 0.1 * pos(0.5 - x),
    })
    a = fictus.Problem.from_dict(expressions).solve()
    b = fictus.Problem.from_dict(callables).solve()
    np.testing.assert_allclose(a.lambda_, b.lambda_, rtol=1e-10, atol=1e-12)
    np.testing.assert_array_equal(a.contact, b.contact)
    for key in ("rel_l2_omega", "rel_h1_omega", "rel_l2_gamma"):
        assert a.errors[key] == pytest.approx(b.errors[key], rel=1e-8), key
    assert a.errors["rel_l2_omega"] < 1e-3


def test_keyword_arguments_and_arrays():
    s = fictus.Problem(geometry=CIRCLE["geometry"], N=64, variant="nonsmooth", f="10 * (x - 0.5)", g="0").solve()
    assert s.u.shape == (65, 65) and s.x.shape == (65,) and s.y.shape == (65,)
    assert np.all(s.u[0, :] == 0) and np.all(s.u[:, 0] == 0)
    assert s.points.shape == (s.multipliers, 2) and s.normals.shape == (s.multipliers, 2)
    np.testing.assert_allclose(np.hypot(s.normals[:, 0], s.normals[:, 1]), 1.0, rtol=1e-12)
    gap = s.u_gamma - s.g
    assert np.all(gap[s.contact] == pytest.approx(0.0, abs=1e-10))
    assert np.all(s.dudn[~s.contact] == pytest.approx(0.0, abs=1e-10))
    assert s.signorini["max_complementarity"] <= 1e-10
    assert s.timings["total"] > 0 and s.errors is None
    assert s.points.base is not None  # a view of the solver's memory, not a copy


@pytest.mark.parametrize("config, message", [
    (dict(CIRCLE, data={"f": "1", "g": "0"}, solver={"tolerance": 1e-8}), "solver.tolerance: unknown key"),
    (dict(CIRCLE, data={"f": "sin(x", "g": "0"}), "data.f: cannot parse"),
    (dict(CIRCLE, data={"f": "1", "g": "0", "c": float("nan")}), "data.c: must be finite"),
    (dict(CIRCLE, data={"f": "1", "g": "0"}, formulation={"multipliers": 5000}), "formulation.multipliers"),
])
def test_bad_input_raises_with_the_cli_message(config, message):
    with pytest.raises(ValueError, match=message.replace("(", r"\(")):
        fictus.Problem.from_dict(config).solve()


def test_new_user_first_tries():
    # a square: simple, solved with the non-smooth variant without asking, and said so
    square = {"geometry": {"shape": "polygon", "vertices": [[0.3, 0.3], [0.7, 0.3], [0.7, 0.7], [0.3, 0.7]]},
              "domain": {"N": 64}, "data": {"f": "10 * (x - 0.5)", "g": "0"}}
    s = fictus.Problem.from_dict(square).solve()
    assert s.converged and s.options["variant"] == "nonsmooth"
    assert any("formulation.variant: γ has corners" in w for w in s.warnings)
    # a coarse grid: the default offset fits itself, with a warning naming the N that keeps it
    s = fictus.Problem.from_dict(dict(CIRCLE, domain={"N": 64}, data={"f": "1", "g": "0"})).solve()
    assert s.converged and any("does not fit at N = 64" in w for w in s.warnings), s.warnings
    assert s.multipliers > 15  # the default rule gives 15 points; the fitted one brings them closer
    # a misspelt key names the nearest one
    with pytest.raises(ValueError, match='geometry.raduis: unknown key \\(did you mean "radius"\\?\\)'):
        fictus.Problem.from_dict({"geometry": {"shape": "circle", "center": [0.5, 0.5], "raduis": 0.3},
                                  "data": {"f": "1", "g": "0"}})
    with pytest.raises(ValueError, match='did you mean "threads"'):
        fictus.Problem(geometry=CIRCLE["geometry"], f="1", g="0", threds=2)


def test_callable_errors_are_reported():
    def broken(x, y):
        raise ZeroDivisionError("boom")
    with pytest.raises(ValueError, match="data.f: the callable failed: .*boom"):
        fictus.Problem.from_dict(dict(CIRCLE, data={"f": broken, "g": "0"})).solve()


def test_newton_failure_raises_runtime_error():
    with pytest.raises(RuntimeError, match="solver.max_newton: Newton did not converge"):
        fictus.Problem.paper(N=128, variant="nonsmooth", max_newton=1).solve()


def test_solve_releases_the_gil():
    ticks = []
    problem = fictus.Problem.paper(N=1024)
    worker = threading.Thread(target=problem.solve)
    worker.start()
    while worker.is_alive():
        ticks.append(time.perf_counter())
        time.sleep(0.001)
    worker.join()
    assert len(ticks) > 20  # the main thread ran while the solver worked


def test_trace_rule_and_independent_check():
    # The reconstructed traces (default) against the paper-style shifted rule on the non-smooth
    # variant of the paper's problem at N = 256: the kink-corrected field is far more accurate, and
    # both report the Signorini conditions with an independent ∂u/∂n.
    new = fictus.Problem.paper(N=256, variant="nonsmooth").solve()
    old = fictus.Problem.paper(N=256, variant="nonsmooth", normal_derivative="shifted").solve()
    assert new.options["normal_derivative"] == "reconstructed" and old.options["normal_derivative"] == "shifted"
    assert new.errors["rel_l2_omega"] < 0.1 * old.errors["rel_l2_omega"]  # 5.8e-4 vs 2.0e-2
    for s in (new, old):
        check = s.signorini["check"]
        assert set(check) == {"rule", "min_normal_derivative", "max_complementarity", "max_difference",
                              "rms_difference", "relative_difference"}
        assert check["max_difference"] >= check["rms_difference"] >= 0
        assert 0 < check["relative_difference"] == pytest.approx(
            check["rms_difference"] / np.max(np.abs(s.dudn)), rel=1e-12)
    assert "kink-corrected" in new.signorini["check"]["rule"]
    assert new.errors["max_normal_derivative_at_points"] < old.errors["max_normal_derivative_at_points"]


# ---- hostile input: each raises a clean error naming what is wrong ----

SMALL = dict(N=64, geometry=dict(shape="circle", center=[0.5, 0.5], radius=0.25), variant="nonsmooth")


def test_absurd_thread_counts_are_rejected():
    with pytest.raises(ValueError, match="solver.threads: must be in 0"):
        fictus.Problem(**SMALL, f="1", g="0", threads=10**6).solve()


def test_deep_or_self_referential_values_are_rejected():
    deep = {}
    node = deep
    for _ in range(200000):
        node["a"] = {}
        node = node["a"]
    with pytest.raises(ValueError, match="nested more than"):
        fictus.Problem(**SMALL, f="1", g="0", domain=deep)
    looped = {}
    looped["self"] = looped
    with pytest.raises(ValueError, match="nested more than"):
        fictus.Problem(**SMALL, f="1", g="0", solver=looped)


@pytest.mark.parametrize("bad", [lambda x, y: x + 1j * y, lambda x, y: np.array(["a"] * len(x))])
def test_callables_must_return_real_numbers(bad):
    with pytest.raises(ValueError, match="data.g: the callable failed: the callable must return real numbers"):
        fictus.Problem(**SMALL, f="1", g=bad).solve()


def test_keyboard_interrupt_in_a_callable_stays_a_keyboard_interrupt():
    def g(x, y):
        raise KeyboardInterrupt
    with pytest.raises(KeyboardInterrupt):
        fictus.Problem(**SMALL, f="1", g=g).solve()


def test_result_views_are_read_only_and_a_missing_field_is_an_error():
    s = fictus.Problem(**SMALL, f="1", g="0").solve(field=False)
    for name in ["lambda_", "g", "u_gamma", "dudn", "s", "points", "normals"]:
        array = getattr(s, name)
        assert not array.flags.writeable, name
        with pytest.raises(ValueError):
            array[0] = 1.0
    with pytest.raises(ValueError, match="the field was not computed"):
        s.u


def test_each_solve_has_its_own_callable_errors():
    calls = {"n": 0}

    def g(x, y):  # fails on its first call only
        calls["n"] += 1
        if calls["n"] == 1:
            raise RuntimeError("first call fails")
        return 0 * x
    p = fictus.Problem(**SMALL, f="1", g=g)
    with pytest.raises(ValueError, match="first call fails"):
        p.solve()
    assert p.solve().converged  # the earlier solve's error does not leak into this one


@pytest.mark.parametrize("schur, N", [("green", 4096), ("krylov", 1024)])  # uninterrupted: ≈ 3 s and ≈ 10 s
def test_ctrl_c_stops_a_solve_within_a_fraction_of_a_second(schur, N):
    import signal
    p = fictus.Problem.paper(N=N, variant="smooth", schur=schur, krylov_tolerance=1e-12)
    start = time.perf_counter()
    threading.Timer(0.3, lambda: os.kill(os.getpid(), signal.SIGINT)).start()
    with pytest.raises(KeyboardInterrupt):
        p.solve()
    stopped = time.perf_counter() - start
    assert stopped < 0.3 + 1.0, f"stopped {stopped:.2f} s after the start, the signal came at 0.3 s"
    assert fictus.Problem.paper(N=128).solve().converged  # the module is still usable


def test_parameters_and_the_contact_summary_match_the_cli(tmp_path):
    path = os.path.join(EXAMPLES, "parameters.toml")
    results, _ = cli_solve(tmp_path, path, "--N", "128", "--parameter", "height=0.02")
    with open(path) as handle:
        text = handle.read().replace("N = 256", "N = 128").replace("height = 0.0", "height = 0.02")
    s = fictus.Problem.from_toml(text).solve()
    for key, value in results["contact"].items():
        if key == "fit":  # the contact fit's passes (its seconds are this run's)
            assert s.contact_summary[key]["passes"] == value["passes"] >= 1
            assert s.contact_summary[key]["newton_steps"] == value["newton_steps"]
            assert s.contact_summary[key]["moved"] == pytest.approx(value["moved"], rel=1e-9, abs=1e-12)
        elif isinstance(value, str):
            assert s.contact_summary[key] == value, key
        elif isinstance(value, list):  # the contact ends, one row per point, and (3-D) their lines
            got = np.asarray(s.contact_summary[key])
            assert got.shape[0] == len(value), key
            if value:
                np.testing.assert_allclose(got, np.array(value), rtol=1e-12, atol=1e-15)
        else:
            assert s.contact_summary[key] == pytest.approx(value, rel=1e-12, abs=1e-15), key
    for key, value in results["domain"].items():
        assert s.domain[key] == pytest.approx(value, rel=1e-12, abs=1e-15), key
    for key, value in results["estimate"].items():
        if key != "seconds":
            assert s.estimate[key] == pytest.approx(value, rel=1e-9, abs=1e-15), key
    assert s.contact_summary["points"] == int(s.contact.sum())
    d = fictus.Problem.from_dict({**CIRCLE, "parameters": {"a": 0.05},
                                  "data": {"f": "-1", "g": "a * x"}}).solve()
    e = fictus.Problem.from_dict({**CIRCLE, "data": {"f": "-1", "g": "0.05 * x"}}).solve()
    np.testing.assert_array_equal(d.lambda_, e.lambda_)


def test_surface_problem_matches_the_cli(tmp_path):
    """3-D: the manufactured sphere from its file, by the CLI and by Python, gives the same numbers."""
    path = os.path.join(EXAMPLES, "manufactured_sphere.toml")
    results, points = cli_solve(tmp_path, path, "--N", "64", "--m", "129")
    with open(path) as handle:
        text = handle.read().replace("N = 80", "N = 64").replace('variant = "smooth"', 'variant = "smooth"\nmultipliers = 129')
    s = fictus.SurfaceProblem.from_toml(text).solve()
    assert results["dim"] == 3 and s.multipliers == results["multipliers"] == 129
    assert s.iterations == results["newton"]["iterations"]
    assert abs(s.errors["rel_l2_omega"] - results["errors"]["rel_l2_omega"]) < 1e-12
    assert s.estimate["N"] == results["estimate"]["N"] == 32
    assert s.domain["flux"] == pytest.approx(results["domain"]["flux"], rel=1e-12) == results["contact"]["force"]
    assert np.allclose(s.lambda_, [float(p["lambda"]) for p in points], rtol=1e-12, atol=1e-12)
    assert s.u.shape == (65, 65, 65) and s.points.shape == (129, 3)
    assert list(s.contact) == [p["contact"] == "1" for p in points]
    check = s.signorini["check"]  # the independent ∂u/∂n, in 3-D as in 2-D
    assert check["rule"] == results["signorini"]["check"]["rule"]
    for key in ("max_difference", "rms_difference", "relative_difference"):
        assert check[key] == pytest.approx(results["signorini"]["check"][key], rel=1e-9)
    assert 0 < check["relative_difference"] < 0.05 and "one-sided" in check["rule"]
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkIOXML import vtkXMLImageDataReader
    reader = vtkXMLImageDataReader()
    reader.SetFileName(str(tmp_path / "cli" / "solution.vti"))
    reader.Update()
    u_cli = vtk_to_numpy(reader.GetOutput().GetPointData().GetArray("u")).reshape(65, 65, 65)
    assert np.array_equal(s.u, u_cli)  # the same field, in the same [k, j, i] order as the ParaView file
    x, y, z = s.axes
    assert x[0] == 0 and z[-1] == 1 and len(y) == 65


def test_surface_problem_from_a_dict_and_its_errors():
    config = dict(domain=dict(N=32), geometry=dict(shape="sphere", center=[0.5, 0.5, 0.5], radius=0.2),
                  formulation=dict(variant="nonsmooth"), data=dict(f="-1", g="0.2 * (x - 0.5)"))
    s = fictus.SurfaceProblem.from_dict(config).solve()
    assert s.signorini["min_gap"] > -1e-12 and s.signorini["max_complementarity"] < 1e-12
    assert s.errors is None and 0 < np.count_nonzero(s.contact) < s.multipliers
    with pytest.raises(ValueError, match="geometry.radius"):
        fictus.SurfaceProblem(geometry=dict(shape="sphere", center=[0.5, 0.5, 0.5], radius=-1), data=dict(f="1", g="0"))
    sphere = dict(domain=dict(N=32), geometry=dict(shape="sphere", center=[0.5, 0.5, 0.5], radius=0.2),
                  formulation=dict(variant="nonsmooth"))

    def broken(x, y, z):
        raise ZeroDivisionError("boom")
    with pytest.raises(ValueError, match=r"^data.f: the callable failed: ZeroDivisionError: boom$"):
        fictus.SurfaceProblem(**sphere, data=dict(f=broken, g="0")).solve()
    with pytest.raises(ValueError, match="data.g: the callable failed: .*takes 2 positional arguments but 3"):
        fictus.SurfaceProblem(**sphere, data=dict(f="1", g=lambda x, y: x)).solve()
    with pytest.raises(ValueError, match="data.exact: the callable failed: the callable must return real numbers"):
        fictus.SurfaceProblem(**sphere, data=dict(f="1", g="0", exact=lambda x, y, z: x + 0j)).solve()
    with pytest.raises(ValueError, match="data.f: the callable failed: .*one number per point"):
        fictus.SurfaceProblem(**sphere, data=dict(f=lambda x, y, z: x[:3], g="0")).solve()


def test_surface_problem_leaves_the_callers_dicts_alone():
    """Callables are replaced by placeholders in a copy: the same data dict builds a second problem."""
    data = dict(f=lambda x, y, z: 10 * (x - 0.5), g="0.05 * sin(3 * z)")
    geometry = dict(shape="sphere", center=[0.5, 0.5, 0.5], radius=0.2)
    first = fictus.SurfaceProblem(domain=dict(N=32), geometry=geometry, formulation=dict(variant="nonsmooth"), data=data)
    assert callable(data["f"]) and "dim" not in geometry
    second = fictus.SurfaceProblem.from_dict(dict(domain=dict(N=32), geometry=geometry,
                                                  formulation=dict(variant="nonsmooth"), data=data))
    np.testing.assert_array_equal(first.solve().lambda_, second.solve().lambda_)
    assert np.count_nonzero(second.solve().contact) > 0


def test_ctrl_c_inside_a_3d_callable_stops_the_solve():
    """SIGINT while a callable runs raises KeyboardInterrupt inside it: the solve stops at its next check
    (here within the load, about 4 s uninterrupted) and calls no more Python."""
    import signal
    calls = []

    def slow(x, y, z):
        calls.append(len(x))
        time.sleep(0.001)
        return x * 0 + 1.0
    p = fictus.SurfaceProblem(domain=dict(N=64), geometry=dict(shape="sphere", center=[0.5, 0.5, 0.5], radius=0.3),
                              formulation=dict(variant="nonsmooth"), data=dict(f=slow, g="1"), solver=dict(threads=2))
    start = time.perf_counter()
    threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT)).start()
    with pytest.raises(KeyboardInterrupt):
        p.solve()
    assert time.perf_counter() - start < 1.5
    made = len(calls)
    time.sleep(0.2)
    assert len(calls) == made and made < 64 * 64


def test_surface_solution_reports_the_nested_start():
    sphere = dict(geometry=dict(shape="sphere", center=[0.5, 0.5, 0.5], radius=0.3),
                  formulation=dict(variant="nonsmooth"), data=dict(f="-1", g="0.2 * (x - 0.5)"))
    plain = fictus.SurfaceProblem(domain=dict(N=64), solver=dict(threads=2, nested_start=0), **sphere).solve()
    nested = fictus.SurfaceProblem(domain=dict(N=64), solver=dict(threads=2, nested_start=64), **sphere).solve()
    assert plain.nested_start is None
    assert nested.nested_start["N"] == 32 and nested.nested_start["newton_steps"] >= 1, nested.nested_start
    assert "nested_start" in nested.timings
    assert np.array_equal(nested.contact, plain.contact)
    assert np.abs(nested.lambda_ - plain.lambda_).max() <= 1e-9 * np.abs(plain.lambda_).max()
    odd = fictus.SurfaceProblem(domain=dict(N=63), solver=dict(threads=2, nested_start=60), **sphere).solve()
    assert odd.nested_start["skipped"] == "N is odd", odd.nested_start


def test_surface_solution_reports_the_flux_balance():
    sphere = dict(domain=dict(N=48), geometry=dict(shape="sphere", center=[0.5, 0.5, 0.5], radius=0.3),
                  data=dict(f="-1", g="0.2 * (x - 0.5)"))
    balanced = fictus.SurfaceProblem(formulation=dict(variant="nonsmooth"), solver=dict(threads=2), **sphere).solve()
    without = fictus.SurfaceProblem(formulation=dict(variant="nonsmooth", flux_balance=False), solver=dict(threads=2),
                                    **sphere).solve()
    smooth = fictus.SurfaceProblem(formulation=dict(variant="smooth", multipliers=129), solver=dict(threads=2),
                                   **dict(sphere, domain=dict(N=64))).solve()
    assert set(balanced.flux_balance) == {"scatter", "mean", "data_shift"}
    assert 0 < balanced.flux_balance["scatter"] < 0.1, balanced.flux_balance
    assert "flux_balance" in balanced.timings
    assert without.flux_balance is None and smooth.flux_balance is None


def numpy_function(text):
    """A problem file's expression ("q0 = ..., q1 = ..., result": muParser syntax) as a numpy callable f(x, y, z)."""
    parts, depth, start = [], 0, 0
    for k, ch in enumerate(text):
        depth += {"(": 1, ")": -1}.get(ch, 0)
        if ch == "," and depth == 0:
            parts.append(text[start:k])
            start = k + 1
    parts.append(text[start:])
    code = [p.strip().replace("^", "**") for p in parts]
    steps = [(line.split("=", 1)[0].strip(), compile(line.split("=", 1)[1].strip(), "data", "eval")) for line in code[:-1]]
    result = compile(code[-1], "data", "eval")
    names = dict(sin=np.sin, cos=np.cos, exp=np.exp, sqrt=np.sqrt, max=np.maximum)

    def f(x, y, z):
        scope = dict(names, x=x, y=y, z=z)
        for name, value in steps:
            scope[name] = eval(value, scope)
        return eval(result, scope) + 0 * x
    return f


def test_surface_problem_with_numpy_callables_matches_expressions():
    """3-D data as numpy callables f(x, y, z) give the numbers of the same data as expressions: the load,
    g at the points and the errors (∇u by central differences in batches) all go through them."""
    with open(os.path.join(EXAMPLES, "manufactured_sphere.toml")) as handle:
        text = handle.read().replace("N = 80", "N = 48").replace('variant = "smooth"', 'variant = "nonsmooth"')
    a = fictus.SurfaceProblem.from_toml(text).solve()
    data = {}
    for key in ("f", "g", "exact"):
        line = next(line for line in text.splitlines() if line.startswith(key + " = "))
        data[key] = numpy_function(line.split(" = ", 1)[1].strip().strip('"'))
    b = fictus.SurfaceProblem(domain=dict(N=48), geometry=dict(shape="sphere", center=[0.5, 0.5, 0.5], radius=0.3),
                              formulation=dict(variant="nonsmooth"), data=data).solve()
    assert b.multipliers == a.multipliers and b.iterations == a.iterations
    np.testing.assert_allclose(b.lambda_, a.lambda_, rtol=1e-9, atol=1e-11)
    np.testing.assert_array_equal(b.contact, a.contact)
    np.testing.assert_allclose(b.u, a.u, rtol=0, atol=1e-11)
    for key in ("rel_l2_omega", "rel_h1_omega", "rel_l2_gamma"):
        assert b.errors[key] == pytest.approx(a.errors[key], rel=1e-6), key
    assert a.errors["rel_l2_omega"] < 6e-4 and np.count_nonzero(a.contact) > 0.2 * a.multipliers


def test_surface_from_numpy_arrays_solves_like_the_sphere():
    """3-D: a sphere given as vertices and faces (5120 triangles) answers as the analytic sphere does, up to
    the facets; an inward mesh is reoriented with a warning; bad arrays get errors naming the key."""
    vertices, faces = fictus.icosphere(4, [0.5, 0.5, 0.5], 0.2)
    assert vertices.shape == (2562, 3) and faces.shape == (5120, 3)
    common = dict(domain=dict(N=48), formulation=dict(variant="smooth", multipliers=60),
                  data=dict(f="-1", g="0.2 * (x - 0.5)"))
    sphere = fictus.SurfaceProblem(geometry=dict(shape="sphere", center=[0.5, 0.5, 0.5], radius=0.2), **common).solve()
    mesh = fictus.SurfaceProblem(geometry=dict(shape="mesh", vertices=vertices, faces=faces), **common)
    assert mesh.warnings == []
    s = mesh.solve()
    assert s.signorini["min_gap"] > -1e-12 and s.signorini["max_complementarity"] < 1e-12
    assert abs(s.u.max() / sphere.u.max() - 1) < 0.03
    assert abs(s.lambda_.sum() / sphere.lambda_.sum() - 1) < 0.03
    assert abs(np.count_nonzero(s.contact) - np.count_nonzero(sphere.contact)) <= 0.15 * np.count_nonzero(sphere.contact)
    inward = fictus.SurfaceProblem(geometry=dict(shape="mesh", vertices=vertices, faces=faces[:, ::-1]), **common)
    assert any("reoriented outward" in w for w in inward.warnings)
    assert np.allclose(inward.solve().lambda_, s.lambda_, rtol=1e-9, atol=1e-12)
    with pytest.raises(ValueError, match="geometry.faces: expected a .k, 3. array"):
        fictus.SurfaceProblem(geometry=dict(shape="mesh", vertices=vertices, faces=faces[:, :2]), **common)
    with pytest.raises(ValueError, match="geometry.faces: vertex index 9999"):
        fictus.SurfaceProblem(geometry=dict(shape="mesh", vertices=vertices, faces=np.full((4, 3), 9999)), **common)
    with pytest.raises(ValueError, match="geometry.vertices: the mesh is not closed"):
        fictus.SurfaceProblem(geometry=dict(shape="mesh", vertices=vertices, faces=faces[1:]), **common)
    with pytest.raises(ValueError, match="geometry.file: missing"):
        fictus.SurfaceProblem(geometry=dict(shape="mesh"), **common)
    with pytest.raises(ValueError, match="geometry.faces: expected integer vertex indices"):
        fictus.SurfaceProblem(geometry=dict(shape="mesh", vertices=vertices, faces=faces * 1.0), **common)
    with pytest.raises(ValueError, match='geometry.vertices: vertices and faces need shape = "mesh"'):
        fictus.SurfaceProblem(geometry=dict(shape="sphere", vertices=vertices, faces=faces), **common)
    with pytest.raises(ValueError, match="geometry.resolution: expected a number"):
        fictus.SurfaceProblem(geometry=dict(shape="mesh", vertices=vertices, faces=faces, resolution="x"), **common)


def test_ctrl_c_stops_a_3d_solve():
    """3-D: SIGINT during a solve (here the non-smooth variant at N = 128, about 10 s uninterrupted) raises
    KeyboardInterrupt within a second, in the load (0.3 s) and in the kink correction (2.5 s)."""
    import signal
    geometry = dict(shape="sphere", center=[0.5, 0.5, 0.5], radius=0.3)
    for delay in (0.3, 2.5):
        p = fictus.SurfaceProblem(domain=dict(N=128), geometry=geometry, formulation=dict(variant="nonsmooth"),
                                  data=dict(f="1", g="1 + 0.5 * (x - 0.5)"), solver=dict(threads=2))
        start = time.perf_counter()
        threading.Timer(delay, lambda: os.kill(os.getpid(), signal.SIGINT)).start()
        with pytest.raises(KeyboardInterrupt):
            p.solve()
        stopped = time.perf_counter() - start
        assert stopped < delay + 1.0, f"stopped {stopped:.2f} s after the start, the signal came at {delay} s"
    assert fictus.SurfaceProblem(domain=dict(N=32), geometry=dict(shape="sphere", center=[0.5, 0.5, 0.5], radius=0.2),
                                 formulation=dict(variant="nonsmooth"),
                                 data=dict(f="-1", g="0.2 * (x - 0.5)")).solve().iterations > 0


def test_one_problem_and_solution_type_in_both_dimensions(tmp_path, monkeypatch):
    """fictus.Problem takes 2-D and 3-D descriptions; Solution has the same attributes in both."""
    circle = fictus.Problem(domain=dict(N=64), geometry=dict(shape="circle", center=[0.5, 0.5], radius=0.25),
                            formulation=dict(variant="nonsmooth"), data=dict(f="-1", g="0.1 * x")).solve()
    sphere = fictus.Problem(domain=dict(dim=3, N=32), formulation=dict(variant="nonsmooth"),
                            geometry=dict(shape="sphere", center=[0.5, 0.5, 0.5], radius=0.25),
                            data=dict(f="-1", g="0.1 * x")).solve()
    assert type(circle) is fictus.Solution and isinstance(sphere, fictus.Solution)
    assert isinstance(sphere, fictus.SurfaceSolution) and (circle.dim, sphere.dim) == (2, 3)
    for s, measure in ((circle, 2 * np.pi * 0.25), (sphere, 4 * np.pi * 0.25 ** 2)):
        m = s.multipliers
        assert s.points.shape == s.normals.shape == s.gamma_points.shape == (m, s.dim)
        assert s.u.ndim == s.dim and len(s.axes) == s.dim and s.u.shape == tuple(len(a) for a in s.axes[::-1])
        assert abs(s.weights.sum() - measure) < 0.02 * measure  # arcs or patch areas cover γ
        assert s.contact_summary["points"] == int(s.contact.sum()) > 0
        assert s.options["dim"] == s.dim and len(s.options["box"]) == 2 * s.dim
        assert s.options["N"] == s.u.shape[0] - 1
    assert "condition_number" in circle.options and "condition_number" in sphere.options
    assert circle.condition_number > 1 and sphere.condition_number > 1  # cond₂ of the Newton matrix in both
    assert "flux_balance" in sphere.options and "flux_balance" not in circle.options
    np.testing.assert_array_equal(sphere.area, sphere.weights)
    with pytest.raises(AttributeError, match="^s: exists in 2-D solutions only"):
        sphere.s
    with pytest.raises(AttributeError, match="^z: exists in 3-D solutions only"):
        circle.z
    # an option of the other dimension is refused, never ignored
    with pytest.raises(ValueError, match=r"^formulation.flux_balance: applies to 3-D problems only"):
        fictus.Problem(flux_balance=False, geometry=dict(shape="circle", center=[0.5, 0.5], radius=0.25),
                       data=dict(f="1", g="0"))
    # a file with a mesh named relative to it, read from another folder
    folder = tmp_path / "case"
    folder.mkdir()
    vertices, faces = fictus.icosphere(3, [0.5, 0.5, 0.5], 0.25)
    with open(folder / "ball.off", "w") as handle:
        handle.write(f"OFF\n{len(vertices)} {len(faces)} 0\n")
        handle.writelines(f"{x!r} {y!r} {z!r}\n" for x, y, z in vertices)
        handle.writelines(f"3 {a} {b} {c}\n" for a, b, c in faces)
    with open(folder / "ball.toml", "w") as handle:
        handle.write('[domain]\ndim = 3\nN = 32\n[geometry]\nshape = "mesh"\nfile = "ball.off"\n'
                     '[formulation]\nvariant = "nonsmooth"\n[data]\nf = "-1"\ng = "0.1 * x"\n')
    monkeypatch.chdir(tmp_path)
    p = fictus.Problem.from_file(str(folder / "ball.toml"))
    assert type(p) is fictus.Problem and p.dim == 3 and p.N == 32
    mesh = p.solve()
    assert mesh.dim == 3 and mesh.converged and 0 < mesh.contact.sum() < mesh.multipliers


@pytest.mark.parametrize("name, replace", [("mixed_heating.toml", ("N = 512", "N = 256")),
                                           ("mixed_heating_3d.toml", ("N = 96", "N = 48"))])
def test_mixed_conditions_match_the_cli(tmp_path, name, replace):
    path = os.path.join(EXAMPLES, name)
    results, points = cli_solve(tmp_path, path, "--N", replace[1].split()[-1], "--error_estimate", "false")
    with open(path) as handle:
        text = handle.read().replace(*replace)
    s = (fictus.SurfaceProblem if "3d" in name else fictus.Problem).from_toml(
        text + "\n[solver]\nerror_estimate = false\n").solve()
    for part in ("signorini", "dirichlet", "neumann"):
        assert results["conditions"][part]["points"] > 0, part
        for key, value in results["conditions"][part].items():
            assert s.contact_summary["conditions"][part][key] == pytest.approx(value, rel=1e-12, abs=1e-12), (part, key)
    junctions = np.array(results["conditions"]["junctions"])
    assert len(junctions) > 0
    np.testing.assert_allclose(s.contact_summary["conditions"]["junctions"], junctions, rtol=1e-12, atol=1e-12)
    condition = np.array([int(p["condition"]) for p in points])
    np.testing.assert_array_equal(s.condition, condition)
    assert s.contact_summary["points"] == int(s.contact.sum()) == results["contact"]["points"]
    assert not np.any(s.contact[condition > 0])  # contact only on the Signorini part
    # the fixed rows hold: u = u_D = 0 on the Dirichlet part, du/dn = 0 on the Neumann part
    assert np.max(np.abs(s.u_gamma[condition == 1])) < 1e-8
    assert np.max(np.abs(s.dudn[condition == 2])) < 1e-8
    with pytest.raises(ValueError, match="conditions.neumann: overlaps conditions.dirichlet"):
        fictus.Problem(geometry={"shape": "circle", "center": [0.5, 0.5], "radius": 0.3}, f="1", g="0", N=64,
                       conditions={"dirichlet": "x < 0.5", "u": "0", "neumann": "y < 0.5"}).solve()
