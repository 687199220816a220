# ancfdrv: the two commands of the README quick start. Both are idempotent and do all
# set-up they need on a fresh Debian/Ubuntu machine: missing apt packages, a .venv with
# the package and its Python dependencies, the Meson build.
#   make demo   the crane-boom example of seed 000 (statics sweep), results in results/
#   make test   the whole test suite (pytest)
#   make bench  every benchmark, one report: results/bench/report.md (BENCH_FLAGS=--quick
#               for the smoke settings, BENCH_FLAGS=--list for the plan; benchmarks/README.md)

SHELL := /bin/bash
PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.ancfdrv-installed
APT_PACKAGES := gfortran libmumps-seq-dev liblapack-dev libopenblas-dev pkg-config
SOURCES := $(shell find fortran python -name '*.f90' -o -name '*.py' -o -name '*.py.in' \
           -o -name '.f2py_f2cmap' \
           -o -name meson.build) \
           meson.build pyproject.toml
DEMO_STATIC := results/boom_static_sweep
DEMO_LUFFING := results/boom_luffing_sweep

.PHONY: demo test bench install system-packages clean

demo: $(STAMP)
	@echo "== Statics (seed 000, Figs. 4-5): 5 angles x 2 masses x 5 meshes, against the closed form"
	$(VENV)/bin/ancf sweep inputs/boom_static.nml --vary boom.angle_deg=0,15,30,45,60 \
	    --vary loads.tip_mass=0,50 --vary beam.nodes=4,10,16,22,28 -o $(DEMO_STATIC)
	@echo "== Luffing dynamics (seed 000, Figs. 6-15): 2 masses x 5 meshes x 2 time steps"
	$(VENV)/bin/ancf sweep inputs/boom_luffing.nml --vary loads.tip_mass=0,50 \
	    --vary beam.nodes=4,10,16,22,28 --vary solver.dt=2e-3,1e-3 -o $(DEMO_LUFFING)
	@echo "== One luffing run, 28 nodes, 50 kg"
	$(VENV)/bin/ancf run inputs/boom_luffing.nml -o results/boom_luffing.h5 --plot

# one pytest worker per core (pytest-xdist), each test file on one worker (its module
# fixtures computed once)
test: $(STAMP)
	$(PY) -m pytest -q -n auto --dist loadfile

BENCH_FLAGS ?=
bench: $(STAMP)
	$(PY) benchmarks/run_all.py $(BENCH_FLAGS)

install: $(STAMP)

# apt packages only when one is missing (root, or sudo when available)
system-packages:
	@missing=""; \
	for p in $(APT_PACKAGES); do dpkg -s $$p >/dev/null 2>&1 || missing="$$missing $$p"; done; \
	if ! $(PYTHON) -c 'import ensurepip, sysconfig, os, sys; sys.exit(not os.path.exists(os.path.join(sysconfig.get_paths()["include"], "Python.h")))' 2>/dev/null; then \
	    missing="$$missing python3-venv python3-dev"; fi; \
	if [ -n "$$missing" ]; then \
	    echo "installing system packages:$$missing"; \
	    if [ "$$(id -u)" -eq 0 ]; then sudo=""; else sudo="sudo"; fi; \
	    $$sudo apt-get update -qq && DEBIAN_FRONTEND=noninteractive $$sudo apt-get install -y -qq $$missing; \
	fi

$(PY): | system-packages
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install -q --upgrade pip

$(STAMP): $(SOURCES) | system-packages $(PY)
	@# an extension module left in the source tree (a copied or in-place build) would be
	@# installed over the fresh build by meson's install_subdir: refuse, naming it
	@stale="$$(ls python/ancfdrv/_kernel*.so 2>/dev/null)"; if [ -n "$$stale" ]; then \
	    echo "error: $$stale is a kernel build inside the source tree; meson would install it" \
	         "over the fresh build. Remove it: rm $$stale" >&2; exit 2; fi
	$(PY) -m pip install -q meson-python meson ninja numpy
	PATH="$(abspath $(VENV))/bin:$$PATH" $(PY) -m pip install -q --no-build-isolation '.[test]'
	touch $(STAMP)

clean:
	rm -rf $(VENV) build results .pytest_cache
