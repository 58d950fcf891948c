# Two set-up commands a fresh machine needs: `make run` and `make test`.
PY ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
SAMPLE ?= corpus/iso-m/sample-pocket.nc

.PHONY: run test bench fuzz clean venv

$(STAMP): pyproject.toml setup.py nctrans/_plainrun.c
	$(PY) -m venv $(VENV)
	$(BIN)/pip install --quiet --upgrade pip
	$(BIN)/pip install --quiet -e '.[dev]'
	$(BIN)/python -m compileall -q nctrans
	touch $(STAMP)

venv: $(STAMP)

run: $(STAMP)
	$(BIN)/nctrans convert $(SAMPLE) --from iso-m --to sinumerik
	$(BIN)/nctrans toolpath $(SAMPLE) --from iso-m --summary
	$(BIN)/nctrans backplot $(SAMPLE) --from iso-m -o out/sample-backplot.html
	@echo "backplot viewer: $(CURDIR)/out/sample-backplot.html"

test: $(STAMP)
	$(BIN)/python -m pytest -q -n 2 --dist loadgroup -p no:cacheprovider --basetemp=$(CURDIR)/.pytest-tmp

# compileall: an editable install writes no bytecode, and where PYTHONDONTWRITEBYTECODE is set no
# run does either; every CLI run would then compile the package again (~70 ms of start-up).
bench: $(STAMP)
	$(BIN)/python -m compileall -q nctrans
	$(BIN)/python bench/bench.py
	$(BIN)/python bench/bench_check.py
	$(BIN)/python bench/bench_backplot.py
	$(BIN)/python bench/bench_structure.py

# FUZZ_SECONDS: coverage-guided (atheris) time per front end; crashes are kept as regression cases
# under tests/data/fuzz-crashes (run by tests/test_fuzz_crashes.py in `make test`). FUZZ_EXAMPLES:
# examples of each long property run (tests/fuzz) after it; then the property tests marked
# long_property run at their full count (make test runs them briefly). Exit 1 when a crash was kept.
FUZZ_SECONDS ?= 120
FUZZ_EXAMPLES ?= 20000
fuzz: $(STAMP)
	$(BIN)/pip install --quiet -e '.[fuzz]'
	status=0; $(BIN)/python fuzz/fuzz_frontends.py $(FUZZ_SECONDS) || status=$$?; \
	NCTRANS_FUZZ_PROFILE_SET=1 NCTRANS_FUZZ_EXAMPLES=$(FUZZ_EXAMPLES) $(BIN)/python -m pytest -q -p no:cacheprovider -n 2 tests/fuzz --hypothesis-profile=fuzz || status=$$?; \
	NCTRANS_FUZZ_PROFILE_SET=1 $(BIN)/python -m pytest -q -p no:cacheprovider -n 2 -m long_property tests || status=$$?; \
	exit $$status

clean:
	rm -rf $(VENV) build *.egg-info
