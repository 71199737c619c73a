# Spinneret's front door. `make demo` and `make test` are all a new machine needs:
# both install missing Debian packages first (as root; otherwise they say what to install).
#   make deps     install missing Debian packages
#   make          build (build/)
#   make test     build, run the suite, then run it again under ASan+UBSan (build-asan/)
#   make demo     build and write the showcase into out/ (also installs imagemagick, for its contact sheets)
#   make bench    run the benchmarks, write bench/results/<machine>.json
#   make fuzz     run every libFuzzer harness FUZZ_SECONDS each (default 60; build-fuzz/)
#   make test-valgrind  the suite under valgrind memcheck (build/; not in CI: see docs/hostile-input.md)
#   make soak     a long run of a 20,000-particle web, SOAK_SECONDS (default 600); not in CI
#   make determinism  same bytes from build/, build-asan/ and the kernels' other versions
#                     (build-noclones/, build-v3/), with 1 and 2 threads
#   make install  install into PREFIX (default /usr/local)

PREFIX ?= /usr/local
JOBS ?= $(shell nproc 2>/dev/null || echo 2)
BUILD_TYPE ?= RelWithDebInfo
CMAKE_FLAGS ?=
WERROR ?= ON

DEPS := cmake pkg-config gcc make libcmocka-dev libcairo2-dev libpng-dev libcjson-dev fonts-dejavu-core \
        libassimp-dev libglfw3-dev libgl-dev libgl1-mesa-dri xvfb xauth ffmpeg povray clang libclang-rt-14-dev
BENCH_DEPS := libbullet-dev g++ libsuitesparse-dev
# the showcase's contact sheets and onion skins (montage, convert)
DEMO_DEPS := imagemagick

.PHONY: all deps deps-bench deps-demo build test test-fast test-asan fuzz fuzz-build demo bench install clean \
        test-valgrind soak determinism

FUZZ_SECONDS ?= 60

all: build

deps:
	@scripts/install-deps.sh $(DEPS)

deps-bench:
	@scripts/install-deps.sh $(DEPS) $(BENCH_DEPS)

deps-demo:
	@scripts/install-deps.sh $(DEPS) $(DEMO_DEPS)

build/CMakeCache.txt:
	cmake -S . -B build -DCMAKE_BUILD_TYPE=$(BUILD_TYPE) -DSPN_WERROR=$(WERROR) $(CMAKE_FLAGS)

build: deps build/CMakeCache.txt
	cmake --build build -j $(JOBS)

build-asan/CMakeCache.txt:
	cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=Debug -DSPN_SANITIZE=ON -DSPN_WERROR=$(WERROR) -DSPN_VIEWER=OFF $(CMAKE_FLAGS)

test-fast: build
	cd build && ctest --output-on-failure -j $(JOBS)

test-asan: deps build-asan/CMakeCache.txt
	cmake --build build-asan -j $(JOBS)
	cd build-asan && ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
	  ctest --output-on-failure -j $(JOBS)

fuzz-build: deps
	CC=clang cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSPN_FUZZ=ON -DSPN_TESTS=OFF \
	  -DSPN_VIEWER=OFF -DSPN_OPENMP=OFF $(CMAKE_FLAGS)
	cmake --build build-fuzz -j $(JOBS)

fuzz: fuzz-build
	FUZZ_SECONDS=$(FUZZ_SECONDS) scripts/fuzz.sh build-fuzz

# The suite, the sanitizer run, and a short fuzzing pass so regressions surface.
test: test-fast test-asan
	$(MAKE) fuzz FUZZ_SECONDS=$(if $(CI),5,3)

test-valgrind: build
	@command -v valgrind >/dev/null || scripts/install-deps.sh valgrind
	scripts/valgrind.sh build

soak: build
	SOAK_SECONDS=$(or $(SOAK_SECONDS),600) scripts/soak.sh build

# The physics kernels' other versions, run here: build-noclones has no
# target_clones (baseline x86-64, libm's fma: what a processor without AVX2
# and FMA runs), build-v3 the same for x86-64-v3 (the AVX2 clone's
# instructions), on a processor that has them. docs/determinism.md.
DET_V3 := $(shell grep -qw avx2 /proc/cpuinfo 2>/dev/null && grep -qw fma /proc/cpuinfo && echo build-v3)
build-noclones/CMakeCache.txt:
	cmake -S . -B build-noclones -DCMAKE_BUILD_TYPE=Release -DSPN_TESTS=OFF -DSPN_VIEWER=OFF \
	  -DCMAKE_C_FLAGS=-DSPN_NO_CLONES $(CMAKE_FLAGS)
build-v3/CMakeCache.txt:
	cmake -S . -B build-v3 -DCMAKE_BUILD_TYPE=Release -DSPN_TESTS=OFF -DSPN_VIEWER=OFF \
	  "-DCMAKE_C_FLAGS=-DSPN_NO_CLONES -march=x86-64-v3" $(CMAKE_FLAGS)

determinism: build build-asan/CMakeCache.txt build-noclones/CMakeCache.txt $(DET_V3:%=%/CMakeCache.txt)
	cmake --build build-asan -j $(JOBS)
	for b in build-noclones $(DET_V3); do cmake --build $$b -j $(JOBS) --target spinneret || exit 1; done
	scripts/determinism.sh build build-asan build-noclones $(DET_V3)

demo: deps-demo build
	@scripts/demo.sh build/spinneret out

bench: deps-bench
	cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DSPN_WERROR=$(WERROR) $(CMAKE_FLAGS)
	cmake --build build -j $(JOBS)
	@scripts/bench.sh build

install: build
	cmake --install build --prefix $(PREFIX)

clean:
	rm -rf build build-asan out
