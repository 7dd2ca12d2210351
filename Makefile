# The two commands of the README:
#   make run   install missing Debian packages, build (Release), reproduce the paper's Tables 1 and 2
#   make test  install missing Debian packages, build (Release), run every test with ctest, then the
#              sanitizer build and its tests (make sanitize)
BUILD_DIR ?= build
JOBS ?= 2
LEVELS ?= 7-12
DEBIAN_PACKAGES = cmake g++ make pkg-config libfftw3-dev libopenblas-openmp-dev libeigen3-dev libcli11-dev \
                  nlohmann-json3-dev libfmt-dev zlib1g-dev libgtest-dev libbenchmark-dev \
                  libmuparser-dev libtomlplusplus-dev libcgal-dev libspectra-dev python3 python3-dev python3-numpy python3-matplotlib \
                  python3-vtk9 python3-pytest pybind11-dev clang-format \
                  python3-venv python3-pip python3-setuptools python3-wheel \
                  libopenmpi-dev openmpi-bin libfftw3-mpi-dev

.PHONY: deps configure build run test sanitize fuzz bench references manufactured format options-table clean

deps:
	@missing=""; for p in $(DEBIAN_PACKAGES); do \
	  dpkg -s $$p >/dev/null 2>&1 || missing="$$missing $$p"; done; \
	if [ -n "$$missing" ]; then \
	  echo "installing Debian packages:$$missing"; \
	  SUDO=""; [ "$$(id -u)" -eq 0 ] || SUDO=sudo; \
	  $$SUDO apt-get update -qq && DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -qq $$missing; \
	fi

configure: deps
	cmake -S . -B $(BUILD_DIR) -DCMAKE_BUILD_TYPE=Release -DFICTUS_MPI=ON

build: configure
	cmake --build $(BUILD_DIR) -j $(JOBS)

run: build
	$(BUILD_DIR)/apps/fictus reproduce --table both --levels $(LEVELS) --out results

test: build
	cd $(BUILD_DIR) && ctest --output-on-failure -LE slow -j $(JOBS)
	$(MAKE) sanitize

# The same code with AddressSanitizer and UndefinedBehaviorSanitizer (+float-cast-overflow), every
# report fatal: the unit tests, the command-line and bad-input tests, the examples and the fuzz
# corpus. (Not the Python module: an instrumented module needs the sanitizer runtime preloaded.)
SANITIZE_DIR ?= build-sanitize
sanitize: deps
	cmake -S . -B $(SANITIZE_DIR) -DCMAKE_BUILD_TYPE=RelWithDebInfo -DFICTUS_SANITIZE=ON -DFICTUS_MPI=ON \
	      -DFICTUS_BUILD_PYTHON=OFF -DFICTUS_BUILD_BENCH=OFF
	cmake --build $(SANITIZE_DIR) -j $(JOBS)
	cd $(SANITIZE_DIR) && ctest --output-on-failure -LE 'slow|convergence|regression' -E 'style|docs|plot' -j $(JOBS)

# Ten minutes of the mutation fuzzer on the Release build (FUZZ_ARGS: e.g. --minutes 2 --seed 7), then
# 2000 mutants of surface-mesh files (tests/fuzz/fuzz_mesh.py);
# new outcomes grow tests/fuzz/corpus, defects go to build/fuzz-findings.
fuzz: build
	/usr/bin/python3 tests/fuzz/fuzz.py run $(BUILD_DIR)/apps/fictus --grow tests/fuzz/corpus \
	  --findings $(BUILD_DIR)/fuzz-findings $(FUZZ_ARGS)
	/usr/bin/python3 tests/fuzz/fuzz_mesh.py $(BUILD_DIR)/apps/fictus --cases 2000 --findings $(BUILD_DIR)/fuzz-findings

bench: build
	$(BUILD_DIR)/bench/fictus_bench --out bench/results $(BENCH_ARGS)
	$(BUILD_DIR)/bench/fictus_bench_3d --out bench/results $(BENCH3D_ARGS)
	/usr/bin/python3 bench/output_memory.py $(BUILD_DIR)/apps/fictus --out bench/results

# Regenerate the fitted-mesh references (FreeFEM, about an hour on one core) and the manufactured
# solutions (sympy); both outputs are committed, so neither is needed to build or test.
references:
	tests/references/generate.sh

manufactured:
	@dpkg -s python3-sympy >/dev/null 2>&1 || { SUDO=""; [ "$$(id -u)" -eq 0 ] || SUDO=sudo; \
	  $$SUDO apt-get update -qq && DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -qq python3-sympy; }
	/usr/bin/python3 tests/convergence/manufactured.py
	cd tests/convergence && PYTHONHASHSEED=0 /usr/bin/python3 manufactured3d.py  # sympy's cse order follows the hash seed

# Rewrite every C++ file in the project's style (.clang-format); the ctest style.clang_format checks it.
FORMAT_FILES = $(shell find src include apps python tests bench -name '*.[ch]pp' ! -name 'manufactured_solutions*.hpp')
format:
	clang-format -i $(FORMAT_FILES)

# Rewrite the options table of docs/problem_files.md from `fictus options --markdown` (a ctest compares them).
options-table: build
	$(BUILD_DIR)/apps/fictus options --markdown > $(BUILD_DIR)/options.md
	sed -i -e '/<!-- options table: generated/,/<!-- end of the options table -->/{//!d}' \
	       -e '/<!-- options table: generated/r $(BUILD_DIR)/options.md' docs/problem_files.md

clean:
	rm -rf $(BUILD_DIR)
