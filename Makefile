# The two commands of the README: `make demo` and `make test`. Both set everything up first.
VENV ?= .venv
BIN := $(VENV)/bin
DEMO_OUT ?= out/demo
SCENARIO := stages/scenario.usda

.PHONY: setup demo test stages bench clean

setup:
	@bash tools/setup.sh

## Validate the shipped demo scenario and render its CCTV and pedestrian-eye cameras into out/demo/.
demo: setup
	$(BIN)/synthua validate stage $(SCENARIO)
	$(BIN)/synthua inspect $(SCENARIO)
	$(BIN)/synthua render $(SCENARIO) --camera /World/Cameras/CCTV --frame 24 --out $(DEMO_OUT)/cctv
	$(BIN)/synthua render $(SCENARIO) --camera /World/Cameras/PedestrianEye --frame 24 --out $(DEMO_OUT)/pedestrian_eye
	@echo "demo: images, labels and frame.json are in $(DEMO_OUT)/cctv and $(DEMO_OUT)/pedestrian_eye"

## The whole test suite (slow tests included).
test: setup
	$(BIN)/python -m pytest -q

## Regenerate the committed demo layers in stages/ from the library code.
stages: setup
	$(BIN)/synthua create street stages

## Render and label timings (not a test: numbers to compare by hand).
bench: setup
	$(BIN)/python tools/bench_render.py

clean:
	rm -rf out .pytest_cache
