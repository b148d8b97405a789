# Set-up contract: on a fresh machine (Python 3.11 + pip), `make demo` and `make test` do everything.
PYTHON ?= python3
VENV   ?= .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.bidmp-installed

.PHONY: demo test bench install clean

# (Re)create the virtual environment and install bidmp (editable) with pinned dependencies.
$(STAMP): pyproject.toml constraints.txt
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -c constraints.txt -e ".[test,bench]"
	touch $(STAMP)

install: $(STAMP)

demo: $(STAMP)
	$(VENV)/bin/bidmp demo

test: $(STAMP)
	$(PY) -m pytest -q

bench: $(STAMP)
	$(PY) benchmarks/bench_dmp.py
	$(PY) benchmarks/bench_extension.py
	$(PY) benchmarks/bench_incremental.py
	$(PY) benchmarks/bench_scenario.py

clean:
	rm -rf $(VENV) bidmp-out .pytest_cache
