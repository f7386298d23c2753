# MPM toolchain. On a fresh Debian 12 machine, as root:
#   make demo   installs what is missing, builds, runs the Taylor bar example end to end
#   make test   installs what is missing, builds, runs the tests (all but the long studies)
#   make bench  the V3 Taylor bar throughput benchmark (particle-steps per second, memory)
#   make test-long   the long studies (minutes to hours)

BUILD ?= build
JOBS ?= $(shell nproc)
CMAKE_FLAGS ?= -DCMAKE_BUILD_TYPE=Release

DEB_PACKAGES = build-essential cmake pkg-config libeigen3-dev libcgal-dev libvtk9-dev \
  libcli11-dev libgtest-dev googletest libtomlplusplus-dev zlib1g-dev xvfb xauth hyperfine \
  gnuplot-nox python3 bc clang-format ccache libmuparser-dev

.PHONY: all deps build demo test test-long bench clean format layout

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

bench: build
	$(MAKE) -C bench BIN=$(abspath $(BUILD))

format:
	clang-format -i $$(git ls-files '*.cpp' '*.hpp')

# The house rules: includes run downward only, file and function sizes, formatting (also in
# make test as Layout.*).
layout:
	for r in includes sizes format; do python3 tests/tools/check_layout.py . $$r || exit 1; done

clean:
	rm -rf $(BUILD)
