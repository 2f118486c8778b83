PY ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

.PHONY: demo test test-slow lint bench mutate clean

$(BIN)/python:
	$(PY) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip

$(STAMP): $(BIN)/python pyproject.toml
	$(BIN)/python -m pip install --quiet -e '.[dev]'
	touch $(STAMP)

demo: $(STAMP)
	$(BIN)/scenegen demo -o report

# The fast suite runs in TEST_JOBS worker processes (pytest-xdist), a test module per
# worker at a time so that a module's shared fixtures are built once; 2 fits a 2-core
# machine. TEST_JOBS=0 runs it in this process.
TEST_JOBS ?= 2
test: $(STAMP)
	$(BIN)/ruff check scenegen trackers tests tools
	HYPOTHESIS_PROFILE=$${HYPOTHESIS_PROFILE:-$$( [ -n "$$CI" ] && echo ci || echo dev )} $(BIN)/python -m pytest -q -n $(TEST_JOBS) --dist loadscope

# The long tests: one module (the damage suites) holds most of their time, so they are
# shared test by test (worksteal), not module by module.
test-slow: $(STAMP)
	$(BIN)/python -m pytest -q -m slow -n $(TEST_JOBS) --dist worksteal

lint: $(STAMP)
	$(BIN)/ruff check scenegen trackers tests tools

bench: $(STAMP)
	$(BIN)/scenegen bench

# Mutation score of the formula modules (cosmic-ray; long, not part of `make test`).
# MODULES: a subset (resampling particle stages sampling meanshift ms-trackers sok hybrid
# annealed shm kalman metrics mot mot-io stats runner summary motion compose ground-truth
# quantize profiles direct integral histogram checks conformance compare distribution
# strategies);
# SAMPLE: mutants per module (0: all). Results in build/mutate/<module>.txt. Some
# functions of one module only: tools/mutation/mutate.py MODULE --only FUNCTION ...
MODULES ?=
SAMPLE ?= 60
mutate: $(STAMP)
	$(BIN)/python tools/mutation/mutate.py --sample $(SAMPLE) $(MODULES)

clean:
	rm -rf $(VENV) report build *.egg-info
