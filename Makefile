# symrot — run `make help` for the list of targets.
PYTHON ?= python3
PIP ?= $(PYTHON) -m pip
PYTEST_ARGS ?=
TEST_JOBS ?= auto
SYMFORCE_VENV ?= /tmp/symforce_venv

.DEFAULT_GOAL := help
.PHONY: audit docs help check-versions setup setup-bench setup-system setup-python test lint typecheck pytest generate check-generated mutations bench clean

help: ## List the targets with what they do
	@grep -E '^[a-zA-Z_-]+:.*## ' $(MAKEFILE_LIST) | awk 'BEGIN {FS = ":.*## "}; {printf "  make %-16s %s\n", $$1, $$2}'

audit: ## Check the paper's equations by machine and regenerate docs/errata.md
	$(PYTHON) -m symrot audit --write docs/errata.md

setup: setup-system setup-python ## Install everything the tests need (Debian packages and Python dev extras)

setup-system: ## Install gcc, clang (+ sanitizer runtime), Eigen (bench peer), a TeX engine and poppler from Debian when missing (needs root)
	@missing=""; \
	command -v gcc >/dev/null || missing="$$missing gcc"; \
	command -v clang >/dev/null || missing="$$missing clang"; \
	test -f "$$(clang -print-file-name=libclang_rt.asan-x86_64.a 2>/dev/null)" || missing="$$missing libclang-rt-dev"; \
	test -f /usr/include/eigen3/Eigen/Geometry || missing="$$missing libeigen3-dev"; \
	command -v pdflatex >/dev/null || missing="$$missing texlive-latex-base texlive-latex-recommended texlive-latex-extra"; \
	command -v pdftotext >/dev/null || missing="$$missing poppler-utils"; \
	if [ -n "$$missing" ]; then \
	  echo "installing:$$missing"; \
	  if [ "$$(id -u)" = 0 ]; then SUDO=""; else SUDO="sudo"; fi; \
	  $$SUDO apt-get update -qq && DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -qq --no-install-recommends $$missing >/dev/null; \
	fi

setup-bench: ## Install the benchmark peer SymForce in a venv (SYMFORCE_VENV, default /tmp/symforce_venv; bench/c_speed.py only)
	test -x $(SYMFORCE_VENV)/bin/python || $(PYTHON) -m venv $(SYMFORCE_VENV)
	$(SYMFORCE_VENV)/bin/pip install -q symforce

setup-python: ## pip install symrot in editable mode with its dev and docs extras, CPU PyTorch and JAX
	$(PIP) install -q -c constraints.txt -e '.[dev]'
	$(PIP) install -q -c constraints.txt torch==2.13.0
	$(PIP) install -q -c constraints.txt -e '.[dev,docs,jax,torch]'

test: lint typecheck pytest ## ruff, mypy and the test suite (tests/test_generated.py checks generated/ as check-generated does)

lint: ## ruff over the package, tests and benchmarks
	$(PYTHON) -m ruff check $(wildcard symrot tests bench)

typecheck: ## mypy over the package
	$(PYTHON) -m mypy

pytest: ## The test suite only, on TEST_JOBS processes (pytest-xdist; default: one per CPU), with the 25 slowest tests listed
	$(PYTHON) -m pytest -n $(TEST_JOBS) --dist worksteal --durations=25 $(PYTEST_ARGS)

docs: ## The documentation site into docs/_build/html (warnings are errors), then the doctests of its examples
	$(PYTHON) -m sphinx -W --keep-going -b html docs docs/_build/html
	$(PYTHON) -m sphinx -W -b doctest docs docs/_build/doctest

check-versions: ## Fail unless the installed SymPy, matplotlib and mpmath are those of constraints.txt
	@$(PYTHON) -c 'import sys, importlib.metadata as m; pins = [l.split("==") for l in open("constraints.txt") if "==" in l and not l.startswith("#")]; bad = [f"{n} {m.version(n)} (constraints.txt: {v.strip()})" for n, v in pins if m.version(n) != v.strip()]; sys.exit("generated/ needs other versions: " + ", ".join(bad) if bad else 0)'

generate: check-versions ## Rewrite generated/ for the named parameterizations (deterministic)
	$(PYTHON) -m symrot.generate generated

check-generated: check-versions ## Fail with a diff when generated/ is stale
	$(PYTHON) -m symrot.generate --check generated

mutations: ## Mutation check (CI runs it after the tests): every fault of bench/mutation_list.py must fail a test of make test; writes docs/mutations.md
	$(PYTHON) bench/mutations.py --out docs/mutations.md

bench: ## Benchmarks (accuracy and speed); writes docs/*.md
	$(PYTHON) -m symrot.generate --list >/dev/null
	@for script in $(filter-out bench/mutation_list.py,$(wildcard bench/*.py)); do echo "== $$script"; \
	  SYMROT_SYMFORCE_PYTHON=$$(test -x $(SYMFORCE_VENV)/bin/python && echo $(SYMFORCE_VENV)/bin/python || echo $(PYTHON)) \
	  $(PYTHON) $$script || exit 1; done

clean: ## Remove build and cache files
	rm -rf build dist *.egg-info .pytest_cache .mypy_cache .ruff_cache .hypothesis
