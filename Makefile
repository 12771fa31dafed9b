# Two entry points for a newcomer: `make book` and `make test`; `make check-book` then opens
# every built page offline in headless Chromium (tools/check_book.py).
# Each bootstraps .venv from requirements.txt when it is missing or out of date.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
# The BLAS settings every solve runs under (gaitlib.blas.SETTINGS; see environment.md); the
# notebook kernel is installed with them too. One BLAS thread per process: on 2 cores
# threading only adds system time.
export OPENBLAS_NUM_THREADS := 1
export OMP_NUM_THREADS := 1
export MKL_NUM_THREADS := 1
# One OpenBLAS kernel on every x86-64 machine (AVX2, "Haswell"; OpenBLAS picks it itself on
# AMD Zen). With the kernel chosen per CPU, an AVX-512 machine computes the data's Fourier
# left leg differently in the last bits, and the gap diagnosis's cache keys (which hash the
# data's numbers) miss every stored solution (see environment.md).
export OPENBLAS_CORETYPE := Haswell
BLAS_VARS := OPENBLAS_NUM_THREADS OMP_NUM_THREADS MKL_NUM_THREADS OPENBLAS_CORETYPE

.PHONY: book test check-book venv data clean

venv: $(STAMP)

$(STAMP): requirements.txt pyproject.toml
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/pip install --quiet --upgrade pip
	$(BIN)/pip install --quiet -r requirements.txt
	$(BIN)/pip install --quiet --no-deps --no-build-isolation -e .
	$(BIN)/python -m ipykernel install --sys-prefix --name python3 $(foreach v,$(BLAS_VARS),--env $(v) $($(v))) >/dev/null
	touch $(STAMP)

# --all: every page is executed again, also when only gaitlib's code changed (without it
# Sphinx rebuilds only the notebooks whose files changed, and figures drawn by changed library
# code stay stale).
book: $(STAMP)
	$(BIN)/jupyter-book build book --all -W -n --keep-going

# Every built page in headless Chromium with the network blocked: math typeset, figures
# loaded, nothing wide cut off; screenshots in book/_build/screenshots/. Installs Debian's
# chromium with apt-get when it is missing. Needs a built book (make book).
check-book: $(STAMP)
	$(BIN)/python tools/check_book.py book/_build/html

test: $(STAMP)
	$(BIN)/python -m pytest tests --durations=25
	$(BIN)/python -m pytest --nbval-lax book --ignore=book/_build -p no:cacheprovider --durations=15

data: $(STAMP)
	$(BIN)/python -m gaitlib data --out data

clean:
	rm -rf book/_build
