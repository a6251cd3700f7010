# veil — the two entry points of the README, plus the plain build.
#   make        configure and build into build/ (the tool is build/veil)
#   make demo   install missing packages, build, render the demo scene
#   make test   install missing packages, build, run every test (ctest)
#   make data   generate the VDBs that data/scenes/vdb_smoke.json and pyro.json render
#   make accuracy  time against error of the GPU path vs the CPU reference
#                  (bench/accuracy --quick, under 2 minutes; FULL=1: the full sweep)
BUILD ?= build
JOBS ?= $(shell nproc 2>/dev/null || echo 2)

.PHONY: all deps build demo test data clean accuracy

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
	@cd $(BUILD) && ctest --output-on-failure -j $(JOBS)

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

clean:
	rm -rf $(BUILD) out
