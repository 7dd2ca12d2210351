#!/usr/bin/env python3
"""The layers of include/fictus/ and src/: grid, then boundary, then solve (io and mpi beside them). A
file of one layer includes only headers of its own layer and the layers before it; io and mpi (the
library fictus_mpi, built with MPI) are used by the CLI, the bindings, the benchmarks and the tests, never
by the core library. Every header and source lies in a layer.

usage: check_layers.py SOURCE_DIR"""
import os
import re
import sys

LAYERS = ["grid", "boundary", "solve"]
BESIDE = ["io", "mpi"]
INCLUDE = re.compile(r'#include\s+"(?:\.\./)?(?:fictus/)?((?:\w+/)?\w+)\.hpp"')  # "../grid/x.hpp" too


def layer_of(path):
    for part in path.split(os.sep):
        if part in LAYERS or part in BESIDE:
            return part
    return None


def main(root):
    problems = []
    for top in ("include/fictus", "src"):
        for folder, _, files in os.walk(os.path.join(root, top)):
            for name in files:
                if not name.endswith((".hpp", ".cpp")):
                    continue
                path = os.path.relpath(os.path.join(folder, name), root)
                own = layer_of(os.path.relpath(path, top))
                if own is None:
                    if path != os.path.join("include", "fictus", "fictus.hpp"):
                        problems.append(f"{path}: not in a layer ({', '.join(LAYERS + BESIDE)})")
                    continue
                with open(os.path.join(root, path), encoding="utf-8") as handle:
                    text = handle.read()
                for included in INCLUDE.findall(text):
                    other = included.split("/")[0] if "/" in included else own  # a file of its own folder
                    if other in BESIDE and own in LAYERS:
                        problems.append(f"{path}: the core library includes {other}/ ({included}.hpp)")
                    elif other in LAYERS and own in LAYERS and LAYERS.index(other) > LAYERS.index(own):
                        problems.append(f"{path} ({own}) includes {included}.hpp, a later layer")
    if problems:
        sys.exit("FAIL:\n" + "\n".join(problems))
    print("layers: grid → boundary → solve (io and mpi beside them) hold in include/fictus and src")


if __name__ == "__main__":
    main(sys.argv[1])
