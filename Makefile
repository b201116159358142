# Two commands on a fresh machine (python3 + make):
#   make demo   set up a virtualenv with plcrt and run the sample programs
#   make test   set up a virtualenv with plcrt and its test tools, run the test suite
#   make panel  set up a virtualenv and serve the course in the browser panel
PYTHON ?= python3
VENV   ?= .venv
BIN     = $(VENV)/bin

.PHONY: demo test bench panel setup clean

# Two stamp files, one per install, each redone when pyproject.toml changes:
#   .installed       plcrt and what running needs (`pip install -e .`, llvmlite
#                    included): demo, panel
#   .installed-test  the test extra on top (pytest, hypothesis, matplotlib,
#                    playwright): test, bench, setup
# so `make demo` stays small and `make test` after it adds only the test tools.
# pip -qq: only errors, so that `make demo` starts with the demo
$(BIN)/.installed: pyproject.toml
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install -qq --upgrade pip
	$(BIN)/python -m pip install -qq -e .
	touch $@

$(BIN)/.installed-test: $(BIN)/.installed pyproject.toml
	$(BIN)/python -m pip install -qq -e '.[test]'
	touch $@

setup: $(BIN)/.installed-test

demo: $(BIN)/.installed
	$(BIN)/plcrt check programs/subroutine.awl
	$(BIN)/plcrt show programs/seal_in.awl --status --scans 3 --set I0.0=1
	$(BIN)/plcrt run programs/seal_in.awl --scans 3 --set I0.0=1 --watch I0.0 --watch Q0.0
	$(BIN)/plcrt run programs/timers.awl --seconds 2.5 --set I0.0=1 --watch T37 --watch Q0.0
	$(BIN)/plcrt run programs/subroutine.awl --scans 1 --set AIW0=25600 --watch VW10 --watch Q0.0 --json
	$(BIN)/plcrt run programs/timers.awl --scans 3000000 --set I0.0=1 --watch Q0.0 --verbose
	$(BIN)/plcrt run programs/timers.awl --seconds 2.5 --set I0.0=1 --watch T37 --watch Q0.0 --json
	$(BIN)/plcrt run programs/em253/pos_goto_r.awl --plant programs/em253/plant.toml --seconds 18 --set M2.0=1 --watch VW106 --watch VD108
	$(BIN)/plcrt run programs/events/pto_count.awl --plant programs/events/pto_count_plant.toml --seconds 1.2 --set M0.0=1 --watch VD200 --watch VW204 --watch VD208
	$(BIN)/plcrt run programs/pid/pid_loop.awl --plant programs/pid/pid_loop_plant.toml --seconds 60 --set I0.0=1 --watch AIW0 --watch AQW0
	$(BIN)/plcrt run programs/uss/drive.awl --plant programs/uss/drive_plant.toml --seconds 6 --watch VD100:REAL --watch VD110:REAL --watch MB3
	$(BIN)/plcrt run programs/modbus/slave.awl --plant programs/modbus/master_plant.toml --seconds 1 --watch VW20 --watch QB0 --watch QB1
	$(BIN)/plcrt run programs/ports/scale.awl --plant programs/ports/scale_plant.toml --seconds 1 --watch VW10 --watch VW12
	$(BIN)/plcrt run examples/bus_drive/bus_drive.awl library/cia402/drive_lib.awl --plant examples/bus_drive/plant.toml --symbols examples/bus_drive/bus_drive_symbols.txt --data examples/bus_drive/bus_drive.db --seconds 2 --set D1_Enable_SW=1 --set D1_Jog_SW=1 --watch VD1036

test: $(BIN)/.installed-test
	$(BIN)/python -m pytest -q -n auto

# the browser panel on http://127.0.0.1:8253/ (PROGRAM=... serves another program)
PROGRAM ?= examples/course/01-seal-in
panel: $(BIN)/.installed
	$(BIN)/plcrt serve $(PROGRAM)

bench: $(BIN)/.installed-test
	$(BIN)/python bench/run.py

clean:
	rm -rf $(VENV) build *.egg-info .pytest_cache .hypothesis
