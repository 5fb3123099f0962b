# Thin wrapper around CMake/CTest. `make demo` and `make test` work on a fresh Debian 12 machine.
BUILD    ?= build
JOBS     ?= $(shell nproc)
GENERATOR = $(shell command -v ninja >/dev/null 2>&1 && echo "-G Ninja")
CMAKE_ARGS ?=

# Every Debian 12 package the project needs (build, tests, GUI, benchmarks and their peers).
# libopenblas0-serial becomes the system's BLAS (Debian's alternatives rank it above ATLAS):
# CHOLMOD's supernodal factorisations of a large map run in half to two thirds of the time, on
# one thread.
DEB_PACKAGES = cmake g++ make ninja-build ccache pkg-config \
  libmrpt-dev mrpt-common mrpt-apps libopencv-dev libeigen3-dev libsuitesparse-dev libopenblas0-serial \
  libwxgtk3.2-dev libgtest-dev libbenchmark-dev zlib1g-dev libzip-dev libceres-dev \
  xvfb xauth opencv-doc plasma-workspace-wallpapers

# Only `make fuzz` needs these (clang and its libFuzzer/sanitizer runtimes).
FUZZ_DEB_PACKAGES = clang-14 libclang-rt-14-dev

FUZZ_BUILD     ?= build-fuzz
FUZZ_SECONDS   ?= 60
FUZZ_TARGETS   ?=
SANITIZE_BUILD ?= build-sanitize

.PHONY: all deps fuzz-deps configure build demo test bench fuzz sanitize clean

all: build

# Installs only what is missing; a no-op when everything is present. sudo when not root.
install_missing = @missing=""; for p in $(1); do \
	  dpkg-query -W -f='$${Status}' $$p 2>/dev/null | grep -q "install ok installed" || missing="$$missing $$p"; \
	done; \
	if [ -n "$$missing" ]; then \
	  SUDO=""; [ "$$(id -u)" = 0 ] || SUDO=sudo; \
	  echo "installing:$$missing"; \
	  $$SUDO apt-get update -qq && DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -q --no-install-recommends $$missing; \
	else echo "deps: all $(words $(1)) Debian packages present"; fi

deps:
	$(call install_missing,$(DEB_PACKAGES))

fuzz-deps: deps
	$(call install_missing,$(FUZZ_DEB_PACKAGES))

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

# libFuzzer on every reader (fuzz/), FUZZ_SECONDS each, in its own clang build tree. The seeds,
# dictionaries and the regression corpus (run by `make test`) are in fuzz/.
fuzz: fuzz-deps
	@test -f $(FUZZ_BUILD)/CMakeCache.txt || CC=clang-14 CXX=clang++-14 cmake -S . -B $(FUZZ_BUILD) $(GENERATOR) \
	  -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g1" -DURBANSLAM_FUZZ=ON \
	  -DURBANSLAM_BUILD_TESTS=OFF -DURBANSLAM_BUILD_BENCH=OFF -DURBANSLAM_BUILD_GUI=OFF
	cmake --build $(FUZZ_BUILD) -j $(JOBS) --target fuzz_targets
	fuzz/run.sh $(FUZZ_BUILD) $(FUZZ_SECONDS) $(FUZZ_TARGETS)

# The test suite and the demo under AddressSanitizer + UndefinedBehaviorSanitizer (gcc, -O1 with
# line tables), LeakSanitizer included. SANITIZE_TESTS: a ctest -R regex to run a subset
# (default: all). SANITIZE_EXCLUDE: the tests left to the optimised build because a sanitized
# sibling runs the same code on less data (they would triple the sanitized run): the library
# merges (MergeCommand joins through them), the FR079 resumes (the Intel one), the CLI resume
# (MapResume), five of the six whole-excerpt localizations (FindsItsPlace, LocalizeCommand),
# the spill equivalence (ScanStore's spill tests), the memory bound (RSS means nothing under
# ASan), the bag mapped twice (RosBag's reader test), the GUI window (the GUI model's tests),
# the largest pose-graph recovery (six smaller ones) and the city drive searched for in another
# city (the same searches and checks run in SessionJoinCity's join, on half the data).
SANITIZE_TESTS ?=
SANITIZE_EXCLUDE ?= ^(SessionMerge\.|MapResume\.Fr079|RunResume\.Continued|Localizer\.(NeverTracks|StaysLost|Recovers|Tracks|Following)|EsdfPipeline\.Spilled|MemoryBound\.Shipped|RosBag\.Maps|GuiSmoke\.Autorun|PoseGraphBackend\.HeadingsFirst|SessionJoinCity\.NeverJoins)
SANITIZE_ENV = ASAN_OPTIONS=abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1 \
  LSAN_OPTIONS=suppressions=$(CURDIR)/tests/lsan-suppressions.txt
sanitize: deps
	@test -f $(SANITIZE_BUILD)/CMakeCache.txt || cmake -S . -B $(SANITIZE_BUILD) $(GENERATOR) \
	  -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1" -DURBANSLAM_SANITIZE=ON \
	  -DURBANSLAM_BUILD_BENCH=OFF
	cmake --build $(SANITIZE_BUILD) -j $(JOBS)
	cd $(SANITIZE_BUILD) && $(SANITIZE_ENV) ctest --output-on-failure -j $(JOBS) $(if $(SANITIZE_TESTS),-R '$(SANITIZE_TESTS)') $(if $(SANITIZE_EXCLUDE),-E '$(SANITIZE_EXCLUDE)')
	$(SANITIZE_ENV) $(SANITIZE_BUILD)/apps/urbanslam/urbanslam run --out $(SANITIZE_BUILD)/demo

clean:
	rm -rf $(BUILD) $(FUZZ_BUILD) $(SANITIZE_BUILD) out
