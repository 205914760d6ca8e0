# satmotor_ros developer entry points.  Every target uses the project's own .venv, which is
# (re)built from requirements.txt and the package's setup files; nothing from the shell's
# Python or ROS environment is relied upon.

# rclpy must only discover nodes on this machine, in a domain of its own.  The discovery
# range is forced; the domain id may be chosen by the caller (.ci/run, `make test
# ROS_DOMAIN_ID=..`), 73 otherwise.
export ROS_AUTOMATIC_DISCOVERY_RANGE := LOCALHOST
ROS_DOMAIN_ID ?= 73
export ROS_DOMAIN_ID

PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.satmotor-installed

.PHONY: all venv run test bench fuzz clean

all: test

venv: $(STAMP)

# Editable install: the CLI and the tests always run the working tree's code (pytest imports
# satmotor_ros from the repository root anyway, as `python -m pytest` puts it on sys.path).
# In this mode the virtual package satmotor_ros.config (config/ has no __init__.py) cannot be
# imported, so the packaged YAMLs are found through the model's source-tree fallback; a
# non-editable install would not change that for the tests.  test_package_build.py checks
# the pip wheel and the colcon install instead.
# AMENT_IGNORE/COLCON_IGNORE keep ament_flake8's directory walk and colcon's package crawl out
# of the venv (its share/ holds the package.xml of every ROS wheel).
$(STAMP): requirements.txt setup.py setup.cfg
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	touch $(VENV)/AMENT_IGNORE $(VENV)/COLCON_IGNORE
	$(PY) -m pip install -r requirements.txt
	$(PY) -m pip install -e .
	touch $@

# The main job: virtual motor, controller and model over ROS through a cycle of speed and
# load steps on water and oil; bags and report.md with plots in out/demo. The demo replaces
# out/demo only if a demo wrote it (a directory of the user's there stops it, as every
# command's --out does): no rm -rf here.
run: $(STAMP)
	$(VENV)/bin/satmotor demo --out out/demo

test: $(STAMP)
	ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST ROS_DOMAIN_ID=$(ROS_DOMAIN_ID) $(PY) -m pytest -q

bench: $(STAMP)
	$(PY) bench/bench_model.py

# Hostile effect files, column mappings and logs through every reader and command, longer than
# the suite's property tests (test/test_fuzz_hostile.py); the counts are in doc/outputs.md.
fuzz: $(STAMP)
	$(PY) bench/fuzz_hostile.py

clean:
	rm -rf $(VENV) build install log out .pytest_cache .hypothesis *.egg-info
	find . -name __pycache__ -type d -prune -exec rm -rf {} +
