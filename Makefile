# rtcli: every target creates .venv and installs what it needs.
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
BASE   := $(VENV)/.installed-base
FULL   := $(VENV)/.installed

.PHONY: demo warmup test test-all golden bench clean

# rtcli and its base dependencies: enough to render with the numpy engine.
$(BASE): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet -e .
	touch $(BASE)

# Everything the tests use: numba (the compiled engine), FLIP, Dask, the preview's server, the test tools.
$(FULL): $(BASE)
	$(PY) -m pip install --quiet -e '.[test,fast,flip,cluster,preview]'
	touch $(FULL)

# The first image at once, with the numpy engine: no numba to install or compile.
demo: $(BASE)
	$(VENV)/bin/rtcli render scenes/whitted.yaml -o whitted.png --stats
	@echo "wrote whitted.png. Next: make warmup (numba's compiled engine, several times faster on big images; it compiles once)"
	@echo "Live in the browser: $(PY) -m pip install -e '.[preview]', then $(VENV)/bin/rtcli preview scenes/whitted.yaml"

# Compile the compiled engine once (numba caches it), so no render waits for it; it says how far it has got.
warmup: $(FULL)
	$(VENV)/bin/rtcli warmup

test: warmup
	$(PY) -m pytest -q -m "not slow"

test-all: warmup
	$(PY) -m pytest -q

golden: $(FULL)
	$(PY) -m pytest -q tests/renders/test_golden.py --update-goldens

bench: warmup
	-$(PY) -m pip install --quiet -e '.[bench]' || echo "the bench extra (mitsuba, embreex) did not install: timing without them"
	$(PY) bench/run.py
	$(PY) bench/run.py --scenes million,torus1m
	$(PY) bench/rays.py
	$(PY) bench/compile.py --runs 1

clean:
	rm -rf $(VENV) *.egg-info whitted.png
