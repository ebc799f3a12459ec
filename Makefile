# Two commands on a fresh machine:  `make play`  and  `make test`.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed

.PHONY: play test test-slow install arenas vehicles bench clean

$(STAMP): pyproject.toml setup.py $(wildcard tanktool/_kernels*.c) tanktool/_kernels.h
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[test,bench,rl,cluster]'
	touch $(STAMP)
	@echo "installed in $(VENV)/: run $(BIN)/tanktool, or 'source $(BIN)/activate' to put tanktool on the PATH"

install: $(STAMP)

## play: set up and start the game on the bundled default arena
play: $(STAMP)
	$(BIN)/tanktool play

## test: set up and run the whole test suite (slow soak/fuzz runs excluded), on every core
test: $(STAMP)
	SDL_VIDEODRIVER=dummy SDL_AUDIODRIVER=dummy $(BIN)/python -m pytest -q -n auto --dist loadscope

## test-slow: only the long soak/fuzz runs
test-slow: $(STAMP)
	SDL_VIDEODRIVER=dummy SDL_AUDIODRIVER=dummy $(BIN)/python -m pytest -q -m slow

## arenas / vehicles: rebuild the derived files of the bundled content
arenas: $(STAMP)
	$(BIN)/python tools/build_arenas.py

vehicles: $(STAMP)
	$(BIN)/python tools/build_vehicles.py

bench: $(STAMP)
	for f in bench/*.py; do $(BIN)/python $$f || exit 1; done

clean:
	rm -rf $(VENV) build *.egg-info .pytest_cache
