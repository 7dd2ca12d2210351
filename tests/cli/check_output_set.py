#!/usr/bin/env python3
"""The output folder as a set: written into a mount point, left as it was by a failing run.

usage: check_output_set.py FICTUS SCRATCH

1. --out on a mount point (a tmpfs mounted here when the user may, else /dev/shm): the files arrive,
   and no temporary folder is left (a temporary folder beside the mount point would be on another
   file system: "Invalid cross-device link").
2. --files results.json,results.json is refused before any work (exit 1) and the earlier run's
   results.json in that folder is untouched.
3. An output folder that cannot be written (/proc/...) is refused before the solve with exit 3 and
   one line naming output.dir.
"""
import os
import shutil
import subprocess
import sys
import tempfile


def run(fictus, *args):
    return subprocess.run([fictus, *args], capture_output=True, text=True)


def check(condition, message):
    if not condition:
        print("FAIL:", message)
        sys.exit(1)


def mount_point(scratch):
    """A mount point to write into, and how to release it."""
    target = tempfile.mkdtemp(prefix="mount-", dir=scratch)
    if os.geteuid() == 0 and subprocess.run(["mount", "-t", "tmpfs", "-o", "size=64m", "none", target],
                                            capture_output=True).returncode == 0:
        return target, lambda: subprocess.run(["umount", target]) and None
    os.rmdir(target)
    if os.path.ismount("/dev/shm") and os.access("/dev/shm", os.W_OK):
        names = ["results.json", "points.csv", "solution.vti", "curves.vtp", "solution.vtm"]
        return "/dev/shm", lambda: [os.remove(os.path.join("/dev/shm", n)) for n in names
                                    if os.path.exists(os.path.join("/dev/shm", n))]
    print("SKIP: no mount point to write into")
    sys.exit(77)


def main(fictus, scratch):
    os.makedirs(scratch, exist_ok=True)
    # 1. a mount point
    target, release = mount_point(scratch)
    try:
        before = set(os.listdir(target))
        r = run(fictus, "solve", "--N", "64", "--variant", "nonsmooth", "--out", target, "--quiet")
        check(r.returncode == 0, f"solve into the mount point {target}: {r.stderr.strip()}")
        made = set(os.listdir(target)) - before
        check("results.json" in made, f"results.json was not written into {target}: {sorted(made)}")
        check(not [n for n in os.listdir(target) if n.startswith(".fictus")],
              f"a temporary folder was left in {target}: {os.listdir(target)}")
    finally:
        release()
    # 2. a repeated name: refused before any work, the earlier run untouched
    folder = os.path.join(scratch, "repeated")
    shutil.rmtree(folder, ignore_errors=True)
    os.makedirs(folder)
    with open(os.path.join(folder, "results.json"), "w") as f:
        f.write("earlier\n")
    r = run(fictus, "solve", "--N", "64", "--files", "results.json,results.json", "--out", folder)
    check(r.returncode == 1, f"a repeated file name gave exit {r.returncode}: {r.stderr.strip()}")
    check(r.stderr.strip() == "fictus: error: output.files: results.json is named twice",
          f"the message: {r.stderr.strip()!r}")
    with open(os.path.join(folder, "results.json")) as f:
        check(f.read() == "earlier\n", "the earlier results.json was replaced")
    check(sorted(os.listdir(folder)) == ["results.json"], f"files were added: {os.listdir(folder)}")
    # 3. an unwritable folder: exit 3 before the solve
    r = run(fictus, "solve", "--N", "64", "--out", "/proc/x/y")
    lines = r.stderr.strip().splitlines()
    check(r.returncode == 3, f"/proc/x/y gave exit {r.returncode}: {r.stderr.strip()}")
    check(len(lines) == 1 and lines[0].startswith("fictus: error: output.dir: cannot write in /proc"),
          f"the message: {r.stderr.strip()!r}")
    check(r.stdout == "", "the solve ran before the folder was checked")
    print("output sets: mount point, repeated name and unwritable folder as expected")


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
