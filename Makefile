# veil — the two entry points of the README, plus the plain build.
#   make        configure and build into build/ (the tool is build/veil)
#   make demo   install missing packages, build, render the demo scene
#   make test   install missing packages, build, run every test (ctest)
#   make data   generate the VDBs that data/scenes/vdb_smoke.json and pyro.json render
#   make accuracy  time against error of the GPU path vs the CPU reference
#                  (bench/accuracy --quick, under 2 minutes; FULL=1: the full sweep)
#   make test-blender  the Blender add-on's tests (tests/blender/: installs blender, python3-numpy,
#               python3-openvdb and python3-openimageio; headless, about half a minute)
#   make test-farm  a turntable on a one-node Slurm cluster started on this machine
#               (installs slurm-wlm, munge and ffmpeg; tests/cli/farm_test.sh; run as root)
#   make peers  veil against OpenVDB's vdb_render, time against error on three VDBs
#               (bench/peers.py: installs libopenvdb-tools and gnuplot; ~30 minutes the
#               first time, the references then cached; PEERS_ARGS="--quick": minutes)
#   make bench-regress BASE=<commit>  this tree's veil against BASE's (built in a worktree under
#               build/regress/), stage by stage and whole process, in turn on a fixed set of scenes
#               (bench/regress.py; REGRESS_ARGS="--runs 7 --scenes demo,cloud"): a benchmark, not a test
#   make fuzz   libFuzzer on the scene parser, the particle readers, the EXR and
#               the OpenVDB readers, frame patterns and a run's files, environment maps, velocities,
#               grids from memory and scenes with them, FUZZ_SECONDS each (default 60), under ASan and
#               UBSan, in build-fuzz/ (scripts/fuzz.sh)
#   make test-sanitize  every test built with AddressSanitizer and UndefinedBehaviorSanitizer
#                  (undefined behaviour fatal) in build-sanitize/; leaks in Mesa and LLVM
#                  (the GL driver) suppressed by tests/support/lsan.supp, never veil's; the driver is
#                  preloaded, so never unloaded, so its leaks have names to suppress
BUILD ?= build
JOBS ?= $(shell nproc 2>/dev/null || echo 2)

.PHONY: all deps build demo test data clean accuracy test-sanitize fuzz peers test-farm test-blender bench-regress
FUZZ_SECONDS ?= 60

all: build

deps:
	@bash scripts/install-deps.sh

$(BUILD)/CMakeCache.txt:
	@cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null

build: $(BUILD)/CMakeCache.txt
	@cmake --build $(BUILD) -j $(JOBS) -- --no-print-directory

demo:
	@$(MAKE) --no-print-directory deps
	@$(MAKE) --no-print-directory build
	@mkdir -p out
	@$(BUILD)/veil render data/scenes/demo.json -o out/demo.exr --png out/demo.png --stats

test:
	@$(MAKE) --no-print-directory deps
	@$(MAKE) --no-print-directory build
	@cd $(BUILD) && ctest --output-on-failure -j $(JOBS) -LE farm

test-blender:
	@$(MAKE) --no-print-directory deps
	@bash scripts/install-bench-deps.sh blender python3-numpy python3-openvdb python3-openimageio
	@$(MAKE) --no-print-directory build
	@cd $(BUILD) && ctest --output-on-failure -L blender

test-farm:
	@$(MAKE) --no-print-directory deps
	@bash scripts/install-bench-deps.sh slurm-wlm munge ffmpeg
	@$(MAKE) --no-print-directory build
	@cd $(BUILD) && ctest --output-on-failure -L farm

data:
	@$(MAKE) --no-print-directory deps
	@$(MAKE) --no-print-directory build
	@$(BUILD)/tests/make_test_vdbs --plume data/generated/smoke_plume.vdb
	@$(BUILD)/tests/make_test_vdbs --pyro data/generated/pyro_plume.vdb

# Results go to docs/results/accuracy[-quick].{csv,png,gp,txt}; references are
# cached in $(BUILD)/bench-cache. Extra arguments: ACCURACY_ARGS="--runs 5".
accuracy:
	@$(MAKE) --no-print-directory deps
	@bash scripts/install-bench-deps.sh || echo "accuracy: going on without gnuplot (CSV, no plot)"
	@$(MAKE) --no-print-directory build
	@test -f data/generated/smoke_plume.vdb || $(MAKE) --no-print-directory data
	@$(BUILD)/bench/accuracy $(if $(FULL),,--quick) $(ACCURACY_ARGS)

bench-regress:
	@test -n "$(BASE)" || { echo "make bench-regress: name the commit to compare with: BASE=<commit>" >&2; exit 2; }
	@$(MAKE) --no-print-directory deps
	@$(MAKE) --no-print-directory data
	@/usr/bin/python3 bench/regress.py --base $(BASE) $(REGRESS_ARGS)

peers:
	@$(MAKE) --no-print-directory deps
	@bash scripts/install-bench-deps.sh libopenvdb-tools gnuplot-nox
	@$(MAKE) --no-print-directory build
	@python3 bench/peers.py $(PEERS_ARGS)

test-sanitize:
	@$(MAKE) --no-print-directory deps
	@cmake -S . -B build-sanitize -DCMAKE_BUILD_TYPE=RelWithDebInfo -DVEIL_SANITIZE=ON >/dev/null
	@cmake --build build-sanitize -j $(JOBS) -- --no-print-directory
	@cd build-sanitize && LD_PRELOAD=$(wildcard /usr/lib/$(shell gcc -print-multiarch)/dri/swrast_dri.so) \
	  ASAN_OPTIONS=detect_leaks=1:verify_asan_link_order=0 \
	  LSAN_OPTIONS=suppressions=$(CURDIR)/tests/support/lsan.supp:print_suppressions=0 \
	  UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 ctest --output-on-failure -j $(JOBS) -LE farm

fuzz:
	@$(MAKE) --no-print-directory deps
	@bash scripts/install-bench-deps.sh clang
	@CC=clang CXX=clang++ cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo -DVEIL_FUZZ=ON \
	  -DVEIL_SANITIZE=ON >/dev/null
	@cmake --build build-fuzz -j $(JOBS) --target fuzz_scene fuzz_particles fuzz_exr fuzz_vdb fuzz_nanovdb fuzz_paths \
	  fuzz_envmap fuzz_velocity fuzz_grid fuzz_arrays make_test_vdbs make_compare_exrs make_env_map veil_cli \
	  -- --no-print-directory
	@bash scripts/fuzz.sh build-fuzz $(FUZZ_SECONDS)

clean:
	rm -rf $(BUILD) build-sanitize build-fuzz out
