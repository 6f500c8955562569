# Two set-up commands on a fresh machine (each makes its own virtual environment):
#   make demo   - simulate the reference rig, run the ROS 2 node graph in closed loop with
#                 the threshold anti-skid controller and record a bag, calibrate and
#                 diagnose synthetic campaigns
#   make test   - lint and run the test suite
PYTHON ?= python3
VENV ?= .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
# DDS never leaves this machine; a private domain unless the caller chose one.
export ROS_AUTOMATIC_DISCOVERY_RANGE := LOCALHOST
export ROS_DOMAIN_ID ?= 42

.PHONY: demo test test-slow bench lint clean

$(STAMP): setup.py setup.cfg
	$(PYTHON) -m venv $(VENV)
	$(BIN)/pip install --quiet --upgrade pip
	$(BIN)/pip install --quiet -e '.[ros,test]'
	touch $(STAMP)

demo: $(STAMP)
	rm -rf out/brake_const_30bar_bag out/rig_threshold
	$(BIN)/landing-gear-sim simulate --pressure-bar 30 -o out/brake_const_30bar.csv --bag out/brake_const_30bar_bag
	$(BIN)/landing-gear-sim simulate --pressure-bar 45 -o out/brake_const_45bar.csv
	$(BIN)/landing-gear-sim simulate --profile osc-low -o out/brake_osc_low.csv
	$(BIN)/landing-gear-sim bode -o out/bode.png
	$(BIN)/landing-gear-sim rig --controller threshold --bag out/rig_threshold
	$(BIN)/landing-gear-sim metrics out/rig_threshold --plot out/rig_threshold.png
	rm -rf out/campaign
	$(BIN)/landing-gear-sim campaign out/campaign --seed 1
	$(BIN)/landing-gear-sim identify out/campaign -o out/calibrated.yaml
	$(BIN)/landing-gear-sim validate out/campaign --config out/calibrated.yaml --report out/validation
	rm -rf out/campaign_delay
	$(BIN)/landing-gear-sim campaign out/campaign_delay --seed 7 --set elements.actuator_delay=true --set actuator.delay_s=0.006
	$(BIN)/landing-gear-sim diagnose out/campaign_delay --json out/diagnosis.json --report out/diagnosis -o out/extended.yaml

# ruff (style), import-linter (the layers: .importlinter), mypy (types: setup.cfg)
lint: $(STAMP)
	$(BIN)/ruff check landing_gear_sim antiskid msg_tools test bench launch
	$(BIN)/lint-imports
	$(BIN)/mypy

test: lint
	$(BIN)/python -m pytest -q -n 2 --dist loadgroup test

test-slow: lint
	$(BIN)/python -m pytest -q -n 2 --dist loadgroup --slow test

bench: $(STAMP)
	$(BIN)/python bench/run.py
	$(BIN)/python bench/identify.py
	$(BIN)/python bench/graph.py
	$(BIN)/python bench/controllers.py
	$(BIN)/python bench/diagnose.py
	$(BIN)/python bench/report.py
	$(BIN)/python bench/sensitivity.py
	$(BIN)/python bench/jacobians.py
	$(BIN)/python bench/io.py
	$(BIN)/python bench/montecarlo.py
	$(BIN)/python bench/history.py
	$(BIN)/python bench/stopping.py
	$(BIN)/python bench/step_logs.py

clean:
	rm -rf $(VENV) out build install log .pytest_cache
	find . -name __pycache__ -type d -prune -exec rm -rf {} +
