# Thin wrapper around CMake/CTest. `make demo` and `make test` work on a fresh Debian 12 machine.
BUILD    ?= build
JOBS     ?= $(shell nproc)
GENERATOR = $(shell command -v ninja >/dev/null 2>&1 && echo "-G Ninja")
CMAKE_ARGS ?=

# Every Debian 12 package the project needs (build, tests, GUI, benchmarks and their peers).
DEB_PACKAGES = cmake g++ make ninja-build ccache pkg-config \
  libmrpt-dev mrpt-common mrpt-apps libopencv-dev libeigen3-dev libsuitesparse-dev \
  libwxgtk3.2-dev libgtest-dev libbenchmark-dev zlib1g-dev libzip-dev libceres-dev \
  xvfb xauth opencv-doc plasma-workspace-wallpapers

.PHONY: all deps configure build demo test bench clean

all: build

# Installs only what is missing; a no-op when everything is present. sudo when not root.
deps:
	@missing=""; for p in $(DEB_PACKAGES); do \
	  dpkg-query -W -f='$${Status}' $$p 2>/dev/null | grep -q "install ok installed" || missing="$$missing $$p"; \
	done; \
	if [ -n "$$missing" ]; then \
	  SUDO=""; [ "$$(id -u)" = 0 ] || SUDO=sudo; \
	  echo "installing:$$missing"; \
	  $$SUDO apt-get update -qq && DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -q --no-install-recommends $$missing; \
	else echo "deps: all $(words $(DEB_PACKAGES)) Debian packages present"; fi

configure: deps
	@test -f $(BUILD)/CMakeCache.txt || cmake -S . -B $(BUILD) $(GENERATOR) -DCMAKE_BUILD_TYPE=Release $(CMAKE_ARGS)

build: configure
	cmake --build $(BUILD) -j $(JOBS)

# The main job on the shipped default rawlog (Intel Research Lab).
demo: build
	$(BUILD)/apps/urbanslam/urbanslam run --out out/demo
	@echo "demo outputs: out/demo/ (grid.png occupancy grid, map.ply point cloud, trajectory_keyframes.tum, stats.json)"

test: build
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS)

bench: build
	@for s in bench/*/run_*.sh; do [ -x "$$s" ] && echo "== $$s" && "$$s" $(BUILD) || true; done

clean:
	rm -rf $(BUILD) out
