# rtcli: every target creates .venv and installs what it needs.
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed

.PHONY: demo warmup test test-all golden bench clean

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e '.[test,fast,flip,cluster]'
	touch $(STAMP)

# Compile the render engine once (about a minute; numba caches it), so no render waits for it.
warmup: $(STAMP)
	$(VENV)/bin/rtcli warmup

demo: warmup
	$(VENV)/bin/rtcli render scenes/whitted.yaml -o whitted.png --stats
	@echo "wrote whitted.png"

test: warmup
	$(PY) -m pytest -q -m "not slow"

test-all: warmup
	$(PY) -m pytest -q

golden: $(STAMP)
	$(PY) -m pytest -q tests/test_golden.py --update-goldens

bench: warmup
	-$(PY) -m pip install --quiet -e '.[bench]' || echo "the bench extra (mitsuba, embreex) did not install: timing without them"
	$(PY) bench/run.py
	$(PY) bench/rays.py

clean:
	rm -rf $(VENV) *.egg-info whitted.png
