#!/usr/bin/env python3
"""Runs every code block of README.md and docs/*.md, so that a wrong example fails the suite.

  ```sh / ```bash    run with bash -e -o pipefail
  ```python          run with the build's python3 and the module on PYTHONPATH
  ```cpp             built as the main() of a CMake project against an installed fictus
                     (find_package(fictus), cmake --install of the build into the scratch folder), run
  ```toml            parsed (tomllib): a problem file or a piece of one
  ```text            not run: synopses, sample output, formulas
A fence without one of these tags is an error, and so is a command (a line starting with fictus,
make, cmake, python3, pip, $ …) in an indented block: commands go in fenced blocks, where they run.
A block may be skipped with the line `<!-- doc-test: skip: <reason> -->` just above its fence.

Blocks run in order, file by file, in one scratch folder that holds `examples` and `build` (links to
the sources' and the build's), with build/apps (the fictus program) first on PATH; a block may use
what an earlier block of the same file wrote.

usage: run_blocks.py SOURCE_DIR BUILD_DIR PYTHON [--only FILE]
"""
import argparse
import glob
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
import tomllib

RUN = {"sh", "bash", "python", "cpp"}
KNOWN = RUN | {"toml", "text"}
COMMAND = re.compile(r"^\s*(\$ |fictus |make |cmake |python3? |pip |\.venv/|PYTHONPATH=|export |cd )")
SKIP = re.compile(r"<!--\s*doc-test:\s*skip:\s*(.*?)\s*-->")


def blocks(path):
    """(line, tag, text, skip reason or None) for each fenced block; problems found on the way."""
    lines = open(path, encoding="utf-8").read().split("\n")
    found, problems = [], []
    k = 0
    while k < len(lines):
        fence = re.match(r"^```(\S*)(.*)$", lines[k])  # the tag, then any info string
        if fence:
            tag, start = fence.group(1), k + 1
            end = start
            while end < len(lines) and not lines[end].startswith("```"):
                end += 1
            if end == len(lines):
                problems.append(f"{path}:{k + 1}: the fence is never closed")
            skip = SKIP.search(lines[k - 1]) if k > 0 else None
            if tag not in KNOWN:
                problems.append(f"{path}:{k + 1}: a fence tagged '{tag}': tag it one of {sorted(KNOWN)}")
            if skip and not skip.group(1):
                problems.append(f"{path}:{k}: a skip needs a reason")
            found.append((k + 1, tag, "\n".join(lines[start:end]) + "\n", skip.group(1) if skip else None))
            k = end + 1
            continue
        # An indented code block: 4 spaces after a blank line (not a list item's continuation).
        if lines[k].startswith("    ") and k > 0 and lines[k - 1].strip() == "":
            j = k
            while j < len(lines) and (lines[j].startswith("    ") or lines[j].strip() == ""):
                if COMMAND.match(lines[j][4:]):
                    problems.append(f"{path}:{j + 1}: a command in an indented block (put it in a ```sh block, "
                                    f"or ```text for a synopsis): {lines[j].strip()[:60]}")
                j += 1
            k = j
            continue
        k += 1
    return found, problems


# No C++ standard set here: the exported targets must carry it (as a user's project would not set it).
CONSUMER = """cmake_minimum_required(VERSION 3.20)
project(doc_block LANGUAGES CXX)
find_package(fictus 0.1 REQUIRED)
add_executable(block main.cpp)
target_link_libraries(block PRIVATE fictus::fictus fictus::fictus_io)
"""


def run_cpp(text, work, scratch, build, env, counter):
    """Builds the block against fictus installed into scratch/prefix (once) and runs it in `work`."""
    prefix = os.path.join(scratch, "prefix")
    if not os.path.isdir(prefix):
        subprocess.run(["cmake", "--install", build, "--prefix", prefix], check=True, capture_output=True)
    project = os.path.join(scratch, f"cpp{counter}")
    os.makedirs(project)
    with open(os.path.join(project, "main.cpp"), "w") as f:
        f.write(text)
    with open(os.path.join(project, "CMakeLists.txt"), "w") as f:
        f.write(CONSUMER)
    binary = os.path.join(project, "build")
    for step in (["cmake", "-S", project, "-B", binary, f"-DCMAKE_PREFIX_PATH={prefix}", "-DCMAKE_BUILD_TYPE=Release"],
                 ["cmake", "--build", binary]):
        r = subprocess.run(step, capture_output=True, text=True)
        if r.returncode != 0:
            return r
    return subprocess.run([os.path.join(binary, "block")], cwd=work, env=env, capture_output=True, text=True,
                          timeout=600)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("source")
    parser.add_argument("build")
    parser.add_argument("python")
    parser.add_argument("--only", help="one Markdown file (relative to the source)")
    args = parser.parse_args()
    source, build = os.path.abspath(args.source), os.path.abspath(args.build)
    files = [os.path.join(source, "README.md")] + sorted(glob.glob(os.path.join(source, "docs", "*.md")))
    if args.only:
        files = [os.path.join(source, args.only)]

    scratch = tempfile.mkdtemp(prefix="fictus-doc-")
    env = dict(os.environ)
    env["PATH"] = os.path.join(build, "apps") + os.pathsep + env.get("PATH", "")
    env["PYTHONPATH"] = os.path.join(build, "python")
    env["MPLBACKEND"] = "Agg"
    counts = {"ran": 0, "parsed": 0, "skipped": 0, "text": 0}
    failures = []
    try:
        for path in files:
            relative = os.path.relpath(path, source)
            work = os.path.join(scratch, relative.replace("/", "_"))
            os.makedirs(work)
            os.symlink(os.path.join(source, "examples"), os.path.join(work, "examples"))
            os.symlink(build, os.path.join(work, "build"))
            found, problems = blocks(path)
            failures += problems
            for line, tag, text, skip in found:
                where = f"{relative}:{line}"
                if skip is not None:
                    counts["skipped"] += 1
                    print(f"skip  {where} ({tag}): {skip}")
                    continue
                if tag not in KNOWN:
                    continue  # reported above
                if tag == "text":
                    counts["text"] += 1
                    continue
                if tag == "toml":
                    try:
                        tomllib.loads(text)
                        counts["parsed"] += 1
                        print(f"ok    {where} (toml parses)")
                    except tomllib.TOMLDecodeError as e:
                        failures.append(f"{where}: the TOML does not parse: {e}")
                    continue
                command = ([args.python, "-"] if tag == "python" else ["bash", "-e", "-o", "pipefail", "-s"])
                start = time.time()
                try:
                    if tag == "cpp":
                        r = run_cpp(text, work, scratch, build, env, counts["ran"])
                    else:
                        r = subprocess.run(command, input=text, cwd=work, env=env, capture_output=True, text=True,
                                           timeout=600)
                except subprocess.TimeoutExpired:
                    r = subprocess.CompletedProcess(command, 124, "", "still running after 600 s")
                seconds = time.time() - start
                counts["ran"] += 1
                if r.returncode != 0:
                    tail = (r.stdout + r.stderr).strip().splitlines()[-8:]
                    failures.append(f"{where} ({tag}) exited {r.returncode}:\n    " + "\n    ".join(tail))
                    print(f"FAIL  {where} ({tag}, {seconds:.1f} s)")
                else:
                    print(f"ok    {where} ({tag}, {seconds:.1f} s)")
    finally:
        shutil.rmtree(scratch, ignore_errors=True)
    print(f"{counts['ran']} blocks run, {counts['parsed']} TOML blocks parsed, {counts['skipped']} skipped with a "
          f"reason, {counts['text']} text blocks")
    if failures:
        print("\n".join(failures))
        sys.exit(1)


if __name__ == "__main__":
    main()
