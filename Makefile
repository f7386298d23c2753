# MPM toolchain. On a fresh Debian 12 machine, as root:
#   make demo   installs what is missing, builds, runs the Taylor bar example end to end
#   make test   installs what is missing, builds, runs the tests (all but the long studies)
#   make bench  the V3 Taylor bar throughput benchmark (particle-steps per second, memory)
#   make test-long   the long studies (minutes to hours)
#   make study  the trade of accuracy against cost and the extremes map (examples/trade,
#               examples/extremes; about 10 minutes of CPU, one thread)

BUILD ?= build
JOBS ?= $(shell nproc)
# Sanitizer and fuzzer builds are heavy: at most two jobs.
FUZZ_JOBS ?= 2
CMAKE_FLAGS ?= -DCMAKE_BUILD_TYPE=Release

DEB_PACKAGES = build-essential cmake pkg-config libeigen3-dev libcgal-dev libvtk9-dev \
  libcli11-dev libgtest-dev googletest libtomlplusplus-dev zlib1g-dev xvfb xauth hyperfine \
  gnuplot-nox python3 bc clang-format ccache libmuparser-dev \
  libopenmpi-dev openmpi-bin

.PHONY: all deps build demo test test-long bench study clean format layout test-asan fuzz

all: build

# Installs only what is missing (dpkg -s), so a second run does nothing.
deps:
	@missing=""; for p in $(DEB_PACKAGES); do \
	  dpkg -s $$p >/dev/null 2>&1 || missing="$$missing $$p"; done; \
	if [ -n "$$missing" ]; then \
	  echo "installing:$$missing"; \
	  if [ "$$(id -u)" -ne 0 ]; then SUDO=sudo; else SUDO=; fi; \
	  $$SUDO apt-get update -qq && \
	  DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -qq --no-install-recommends $$missing; \
	else echo "dependencies: all present"; fi

# ccache, when present, makes rebuilds in other build folders (sanitizers, fuzzers) cheap.
CCACHE := $(shell command -v ccache 2>/dev/null)
ifneq ($(CCACHE),)
CMAKE_FLAGS += -DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache
endif

build: deps
	cmake -S . -B $(BUILD) $(CMAKE_FLAGS)
	cmake --build $(BUILD) -j$(JOBS)

demo: build
	$(MAKE) -C examples/taylor-bar demo BIN=$(abspath $(BUILD))

test: build
	cd $(BUILD) && ctest -LE long --output-on-failure -j$(JOBS) --timeout 900

test-long: build
	cd $(BUILD) && ctest -L long --output-on-failure

# The default test set under AddressSanitizer and UndefinedBehaviorSanitizer (gcc, -O1 -g,
# OpenMP on, asserts on) in build-asan; any report fails the test that caused it.
ASAN_BUILD ?= build-asan
SAN_ENV = ASAN_OPTIONS=detect_leaks=1:abort_on_error=0:strict_string_checks=1 \
  UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1 LSAN_OPTIONS=suppressions=$(abspath tests/tools/lsan.supp)
test-asan: deps
	cmake -S . -B $(ASAN_BUILD) $(filter-out -DCMAKE_BUILD_TYPE=%,$(CMAKE_FLAGS)) \
	  -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g" \
	  -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O1 -g" -DMPM_SANITIZE=address,undefined
	nice -n 10 cmake --build $(ASAN_BUILD) -j$(FUZZ_JOBS)
	cd $(ASAN_BUILD) && $(SAN_ENV) OMP_WAIT_POLICY=passive \
	  ctest -LE long --output-on-failure -j$(FUZZ_JOBS) --timeout 1800

# The libFuzzer harnesses of tests/fuzz (clang, -fsanitize=fuzzer,address,undefined) in
# build-fuzz, each run for FUZZ_SECONDS over its seed corpus (tests/fuzz/corpus/<name>) and the
# inputs it found before (build-fuzz/corpus/<name>). Crashes, hangs (-timeout) and
# out-of-memory inputs (-rss_limit_mb) land in build-fuzz/crashes/<name>/ and stop the target.
FUZZ_BUILD ?= build-fuzz
FUZZ_SECONDS ?= 60
FUZZERS ?= scene mesh stream expression
fuzz: deps
	cmake -S . -B $(FUZZ_BUILD) $(filter-out -DCMAKE_BUILD_TYPE=%,$(CMAKE_FLAGS)) -DMPM_FUZZ=ON \
	  -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=RelWithDebInfo \
	  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g" -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O1 -g"
	nice -n 10 cmake --build $(FUZZ_BUILD) -j$(FUZZ_JOBS)
	for f in $(FUZZERS); do \
	  mkdir -p $(FUZZ_BUILD)/corpus/$$f $(FUZZ_BUILD)/crashes/$$f && \
	  OMP_WAIT_POLICY=passive OMP_NUM_THREADS=1 nice -n 10 $(FUZZ_BUILD)/fuzz_$$f \
	    $(FUZZ_BUILD)/corpus/$$f tests/fuzz/corpus/$$f -dict=tests/fuzz/$$f.dict \
	    -max_total_time=$(FUZZ_SECONDS) -timeout=10 -rss_limit_mb=2048 -max_len=8192 \
	    -artifact_prefix=$(FUZZ_BUILD)/crashes/$$f/ -print_final_stats=1 || exit 1; \
	done

bench: build
	$(MAKE) -C bench BIN=$(abspath $(BUILD))

study: build
	$(MAKE) -C examples/trade study BIN=$(abspath $(BUILD))
	$(MAKE) -C examples/extremes study BIN=$(abspath $(BUILD))

format:
	clang-format -i $$(git ls-files '*.cpp' '*.hpp')

# The house rules: includes run downward only, file and function sizes, formatting (also in
# make test as Layout.*).
layout:
	for r in includes sizes format; do python3 tests/tools/check_layout.py . $$r || exit 1; done

clean:
	rm -rf $(BUILD)
