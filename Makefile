# The two commands of the README: `make demo` and `make test`. Both set everything up first.
VENV ?= .venv
BIN := $(VENV)/bin
DEMO_OUT ?= out/demo
SCENARIO := stages/scenario.usda

.PHONY: setup demo test docs refs stages bench cycles train-env clean

setup:
	@bash tools/setup.sh

## The detector of `synthua train` and `synthua evaluate-real` (Ultralytics, torch, torchvision: about 5.9 GB) in a
## virtual environment of its own, $(TRAIN_VENV) (tools/setup_train.sh; about 2.5 minutes from this disk's wheels).
TRAIN_VENV ?= $(VENV)-train

train-env:
	@TRAIN_VENV=$(TRAIN_VENV) bash tools/setup_train.sh

DISTRICT := stages/district/scenario.usda

## Validate the shipped scenarios, render the demo street's CCTV and pedestrian-eye cameras and the
## Largo da Ordem district's largo CCTV into out/demo/, then generate and verify a small dataset of the
## demo street (configs/demo.json) in out/demo/dataset/ and write its statistics report to out/demo/dataset_report/,
## and a randomised one (configs/demo_random.json: every image a new scene) in out/demo/dataset_random/.
demo: setup
	$(BIN)/synthua validate stage $(SCENARIO)
	$(BIN)/synthua inspect $(SCENARIO)
	$(BIN)/synthua render $(SCENARIO) --camera /World/Cameras/CCTV --time-code 24 --out $(DEMO_OUT)/cctv
	$(BIN)/synthua render $(SCENARIO) --camera /World/Cameras/PedestrianEye --time-code 24 --out $(DEMO_OUT)/pedestrian_eye
	$(BIN)/synthua validate stage $(DISTRICT)
	$(BIN)/synthua render $(DISTRICT) --camera /World/Cameras/CCTV_Largo --time-code 24 --out $(DEMO_OUT)/district_cctv_largo
	@# the demo's dataset is made afresh: a dataset folder only resumes the same job, and a changed scenario is another
	rm -rf $(DEMO_OUT)/dataset
	$(BIN)/synthua generate $(SCENARIO) --config configs/demo.json --out $(DEMO_OUT)/dataset
	$(BIN)/synthua verify $(DEMO_OUT)/dataset
	$(BIN)/synthua stats $(DEMO_OUT)/dataset --out $(DEMO_OUT)/dataset_report
	rm -rf $(DEMO_OUT)/dataset_random
	$(BIN)/synthua generate $(SCENARIO) --config configs/demo_random.json --out $(DEMO_OUT)/dataset_random
	$(BIN)/synthua verify $(DEMO_OUT)/dataset_random
	$(BIN)/synthua stats $(DEMO_OUT)/dataset_random --out $(DEMO_OUT)/dataset_random_report
	@echo "demo: images, labels and frame.json are in $(DEMO_OUT)/{cctv,pedestrian_eye,district_cctv_largo}; a dataset (COCO, panoptic, Cityscapes, YOLO) in $(DEMO_OUT)/dataset, its statistics in $(DEMO_OUT)/dataset_report/report.html; a randomised one (every image a new scene) in $(DEMO_OUT)/dataset_random, its statistics and diversity in $(DEMO_OUT)/dataset_random_report/report.html"

## The whole test suite (slow tests included) on parallel workers (pytest-xdist: $(TEST_WORKERS), one more than
## the cores, at most 8: tests that wait on subprocesses, Ray or a killed job leave a core idle; on 2 cores three
## workers are the fastest, docs/tests.md gives the times; each test file runs on one worker, so its
## module fixtures are built once), then the package's import layers (import-linter's contracts in pyproject.toml),
## the type check of the typed records and their readers (mypy: [tool.mypy] in pyproject.toml)
## and the documentation site built with --strict (a broken link or reference fails). The detector's environment
## first: where it cannot be made, its tests skip with the reason. `make test TEST_WORKERS=1` runs it on one worker.
TEST_WORKERS ?= $(shell n=$$(nproc 2>/dev/null || echo 1); echo $$(( n + 1 > 8 ? 8 : n + 1 )))

test: setup
	-@TRAIN_VENV=$(TRAIN_VENV) bash tools/setup_train.sh
	SYNTHUA_TRAIN_PYTHON=$(TRAIN_VENV)/bin/python $(BIN)/python -m pytest -q -n $(TEST_WORKERS) --dist loadfile --no-loadscope-reorder
	$(BIN)/lint-imports
	$(BIN)/mypy
	NO_MKDOCS_2_WARNING=1 $(BIN)/mkdocs build --strict --quiet --site-dir build/site

## The documentation site from docs/ into site/ (offline: open site/index.html).
docs: setup
	NO_MKDOCS_2_WARNING=1 $(BIN)/mkdocs build --strict

## Regenerate the RGB reference images of the tests (tests/data/refs): only when a change of the renders is
## intended (tools/make_refs.py; the tests compare renders with them statistically).
refs: setup
	$(BIN)/python tools/make_refs.py

## Regenerate the committed demo layers in stages/ from the library code.
stages: setup
	$(BIN)/synthua create street stages
	$(BIN)/synthua create district stages/district --seed 0

## Benchmarks (not tests: ratios and timings measured side by side in one run): rendering through a
## render session (first load, per-frame update, labels, RGB), building the district, imports and agents, the
## amodal pass, dataset workers' memory over 500 images, denoised RGB against 512-spp references, what scene
## randomisation costs per image against a default-quality frame, and issue 11's
## targets against the raw ray bound and Blender Cycles (tools/setup_cycles.sh installs PyPI bpy into
## $(CYCLES_VENV) first; without it the table says Blender is not installed and the rest is measured).
CYCLES_VENV ?= $(VENV)-cycles

cycles:
	@CYCLES_VENV=$(CYCLES_VENV) bash tools/setup_cycles.sh

bench: setup
	-@CYCLES_VENV=$(CYCLES_VENV) bash tools/setup_cycles.sh
	SYNTHUA_CYCLES_PYTHON=$(CYCLES_VENV)/bin/python $(BIN)/python tools/bench_targets.py
	$(BIN)/python tools/bench_render.py
	$(BIN)/python tools/bench_conditions.py
	$(BIN)/python tools/bench_label_agreement.py
	$(BIN)/python tools/bench_memory.py
	$(BIN)/python tools/bench_twin.py
	$(BIN)/python tools/bench_amodal.py
	$(BIN)/python tools/bench_generate.py --memory 500
	$(BIN)/python tools/bench_denoise.py
	$(BIN)/python tools/bench_randomise.py

clean:
	rm -rf out .pytest_cache
