# mbd2d: `make demo` and `make test` set up everything that is missing (system packages,
# a .venv with the build and test tools, the package itself) and then do their job.
SHELL := /bin/bash
VENV ?= .venv
PYTHON ?= python3
PY := $(VENV)/bin/python
export PATH := $(abspath $(VENV))/bin:$(PATH)

PYDEPS := numpy meson meson-python ninja pytest hypothesis matplotlib pillow scipy
# the sweep extra (pyproject.toml): design sweeps, tolerance analysis, Dask, netCDF
PYDEPS += xarray dask distributed h5netcdf h5py pandas tqdm
SOURCES := $(wildcard fortran/*.f90 fortran/app/*.f90 python/mbd2d/*.py python/mbd2d/*/*.py) meson.build pyproject.toml

.PHONY: demo test bench system install clean help

help:
	@echo "make demo   - set up and run the examples (pictures in examples/output/)"
	@echo "make test   - set up and run the test suite"
	@echo "make bench  - set up and run the benchmarks"

system:
	@echo "== system packages: checking gfortran, pkg-config, LAPACK/BLAS, python3-venv (tools/system-deps.sh)"
	@./tools/system-deps.sh

# re-run when the Makefile changes (PYDEPS gained a package)
$(VENV)/.deps-ok: Makefile
	@echo "== $(VENV): creating it with $(PYTHON) and installing $(PYDEPS)"
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install -q --disable-pip-version-check $(PYDEPS)
	touch $@

# a real (non-editable) install, as a user gets from `pip install .`
$(VENV)/.install-ok: $(VENV)/.deps-ok $(SOURCES)
	@echo "== building mbd2d (Fortran core, f2py extension, mbd2d-solve) and installing it into $(VENV)"
	$(PY) -m pip install -q --disable-pip-version-check --no-build-isolation --no-deps .
	touch $@

install: system $(VENV)/.install-ok
	@echo "== set up: $$($(PY) -c 'import mbd2d, sys; print("mbd2d", mbd2d.__version__, "on Python", sys.version.split()[0])') in $(VENV)"

demo: install
	@echo "== running examples/demo.py (pictures and animations in examples/output/)"
	$(PY) examples/demo.py

test: install
	@echo "== running the test suite (pytest tests)"
	$(PY) -m pytest tests

# bench-only packages; Exudyn and pylinkage (the peer comparisons) are optional: without
# them the bench says so and runs the rest
BENCHDEPS := scipy
$(VENV)/.bench-ok: $(VENV)/.deps-ok Makefile
	$(PY) -m pip install -q --disable-pip-version-check $(BENCHDEPS)
	$(PY) -m pip install -q --disable-pip-version-check exudyn || \
		echo "exudyn could not be installed: the benchmarks run without the peer comparison"
	command -v valgrind >/dev/null 2>&1 || ./tools/system-deps.sh valgrind || \
		echo "valgrind could not be installed: the benchmarks run without instruction counts"
	$(PY) -m pip install -q --disable-pip-version-check pylinkage || \
		echo "pylinkage could not be installed: the synthesis bench runs without it"
	touch $@

bench: install $(VENV)/.bench-ok
	$(PY) bench/run.py

clean:
	rm -rf build build-editable examples/output $(VENV)
