#!/usr/bin/env python3
"""The doc test can fail: on a scratch README with a failing block, an untagged fence, a command in
an indented block, a skip without a reason and bad TOML, run_blocks.py exits 1 naming each; on the
same README with those fixed it passes. usage: check_run_blocks.py BUILD_DIR PYTHON"""
import os
import subprocess
import sys
import tempfile

build, python = sys.argv[1:3]
runner = os.path.join(os.path.dirname(os.path.abspath(__file__)), "run_blocks.py")
bad = """# t

```sh
fictus solve --no-such-flag 1
```

```
untagged
```

Text.

    fictus solve examples/circle.toml

<!-- doc-test: skip: -->
```sh
true
```

```toml
[domain
```
"""
good = """# t

```sh
fictus solve --N 128 --out "" --quiet
```

```python
import fictus
assert fictus.Problem.paper(N=128).solve().iterations > 0
```

```text
fictus solve examples/circle.toml
```

<!-- doc-test: skip: shows a skip -->
```sh
false
```

```toml
[domain]
N = 64
```
"""
failures = []
with tempfile.TemporaryDirectory() as source:
    os.makedirs(os.path.join(source, "examples"))
    for text, expected_code, expected in [
        (bad, 1, ["README.md:3 (sh) exited 1", "a fence tagged ''", "a command in an indented block",
                  "a skip needs a reason", "the TOML does not parse"]),
        (good, 0, ["2 blocks run, 1 TOML blocks parsed, 1 skipped with a reason, 1 text blocks"]),
    ]:
        with open(os.path.join(source, "README.md"), "w") as f:
            f.write(text)
        r = subprocess.run([python, runner, source, build, python, "--only", "README.md"], capture_output=True,
                           text=True)
        out = r.stdout + r.stderr
        if r.returncode != expected_code:
            failures.append(f"exit {r.returncode}, expected {expected_code}:\n{out}")
        for e in expected:
            if e not in out:
                failures.append(f"'{e}' not in the output:\n{out}")
if failures:
    print("\n".join(failures))
    sys.exit(1)
print("the doc test fails on bad blocks and passes on good ones")
