# Quick start: `make demo` and `make test` (both set the project up first).
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed

# torch is pinned to the CPU build and installed before stable-baselines3,
# so that the RL extra never pulls the CUDA wheels.
TORCH_PIN := torch==2.13.0

.PHONY: setup demo test test-slow bench validate crosscheck docs clean

setup: $(STAMP)

$(STAMP): pyproject.toml Makefile
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip setuptools wheel
	$(PY) -m pip install --quiet "$(TORCH_PIN)"
	$(PY) -m pip install --quiet -e ".[all]"
	$(PY) -m iceenvs.warmup || echo "warm-up incomplete: the remaining kernels compile on first use"
	touch $(STAMP)

# the engine demo (python -m physics.demo), then the training demo
# (python -m agents.demo), and the total wall time
demo: setup
	$(PY) -m seaice_gym demo

test: setup
	$(PY) -m pytest -q -m "not slow"

test-slow: setup
	$(PY) -m pytest -q -m slow

bench: setup
	$(PY) -m benchmarks.hertz
	$(PY) -m benchmarks.hertz_phases
	$(PY) -m benchmarks.harddisk
	$(PY) -m benchmarks.observables
	$(PY) -m benchmarks.itd
	$(PY) -m benchmarks.environments
	$(PY) -m benchmarks.ship
	$(PY) -m benchmarks.headline

docs: setup
	$(PY) -m sphinx -W --keep-going -b html docs docs/_build/html

validate: setup
	$(PY) -m physics.validate

crosscheck: setup
	$(PY) -m physics.crosscheck all --out docs/crosscheck --force

clean:
	rm -rf $(VENV) build *.egg-info .pytest_cache
	find . -name __pycache__ -type d -prune -exec rm -rf {} +
