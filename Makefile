# Two commands do all set-up on a fresh machine:  make demo  (live demo)  and  make test.
PY      ?= python3
VENV    := .venv
STAMP   := $(VENV)/.installed
export ROS_AUTOMATIC_DISCOVERY_RANGE := LOCALHOST

.PHONY: setup setup-jazzy test-jazzy demo shaping test bench bench-all soak reproduce compare \
	bags survey survey-ambient survey-temperature clean

setup: $(STAMP)

$(STAMP): requirements.txt setup.py setup.cfg package.xml
	test -x $(VENV)/bin/python || $(PY) -m venv $(VENV)
	$(VENV)/bin/pip install --quiet --disable-pip-version-check -r requirements.txt
	$(VENV)/bin/pip install --quiet --disable-pip-version-check --no-deps --no-build-isolation -e .
	@# setup.cfg puts the executables where ros2 run looks (<prefix>/lib/vib_estimator); link them
	@# into .venv/bin as well so they are on the PATH of an activated environment.
	for exe in $(VENV)/lib/vib_estimator/*; do ln -sf ../lib/vib_estimator/$$(basename $$exe) $(VENV)/bin/; done
	@# compile the estimator kernels once, now, into numba's cache (a first node start then takes
	@# a second instead of half a minute)
	$(VENV)/bin/vib-estimator warmup
	touch $(STAMP)

# The Jazzy floor: the suite on what a real ROS 2 Jazzy machine (Ubuntu 24.04) has, numpy 1.26,
# scipy 1.11, numba 0.59, matplotlib 3.6 (requirements-jazzy.txt), in its own venv. Its numba keeps
# its kernels in its own cache: two numba versions on the caches beside the sources
# (__pycache__) would each find the other's index there and recompile everything.
JAZZY       := .venv-jazzy
JAZZY_STAMP := $(JAZZY)/.installed
JAZZY_ENV   := NUMBA_CACHE_DIR=$(CURDIR)/$(JAZZY)/numba-cache

setup-jazzy: $(JAZZY_STAMP)

$(JAZZY_STAMP): requirements-jazzy.txt setup.py setup.cfg package.xml
	test -x $(JAZZY)/bin/python || $(PY) -m venv $(JAZZY)
	$(JAZZY)/bin/pip install --quiet --disable-pip-version-check -r requirements-jazzy.txt
	$(JAZZY)/bin/pip install --quiet --disable-pip-version-check --no-deps --no-build-isolation -e .
	for exe in $(JAZZY)/lib/vib_estimator/*; do ln -sf ../lib/vib_estimator/$$(basename $$exe) $(JAZZY)/bin/; done
	$(JAZZY_ENV) $(JAZZY)/lib/vib_estimator/vib-estimator warmup
	touch $(JAZZY_STAMP)

test-jazzy: setup-jazzy
	$(JAZZY_ENV) $(JAZZY)/bin/python -m pytest -q test

demo: setup
	$(VENV)/bin/vib-estimator demo

shaping: setup
	$(VENV)/bin/vib-estimator demo --shaping

test: setup
	$(VENV)/bin/python -m pytest -q test

bench: setup
	$(VENV)/bin/python benchmarks/bench_estimator.py
	$(VENV)/bin/python benchmarks/bench_accuracy.py
	$(VENV)/bin/python benchmarks/bench_node.py

# every benchmark (long: the precision, modes and survey studies take minutes each)
bench-all: bench
	$(VENV)/bin/python benchmarks/bench_precision.py
	$(VENV)/bin/python benchmarks/bench_target.py
	$(VENV)/bin/python benchmarks/bench_modes.py
	$(VENV)/bin/python benchmarks/bound_modes.py
	$(VENV)/bin/python benchmarks/bench_survey.py
	$(VENV)/bin/python benchmarks/bench_survey_accuracy.py
	$(VENV)/bin/python benchmarks/real_data.py
	$(VENV)/bin/python benchmarks/bench_channels.py
	$(VENV)/bin/python benchmarks/bench_defaults.py

# the nodes for 6 minutes at speed 10 with a fault every 24 s (docs/soak.md); SOAK_ARGS=--sim-hours 8
soak: setup
	$(VENV)/bin/python benchmarks/soak.py $(SOAK_ARGS)

reproduce: setup
	$(VENV)/bin/vib-estimator reproduce fig1 --out out/fig1.png
	$(VENV)/bin/vib-estimator reproduce fig2 --out out/fig2.png

compare: setup
	$(VENV)/bin/vib-estimator compare --out out

bags: setup
	$(VENV)/bin/python scripts/make_bags.py

# a simulated fleet of 40 daily recordings (stiffness 1 % lower from day 30), surveyed against day 0
survey: setup
	$(VENV)/bin/python scripts/make_fleet.py --out out/fleet
	$(VENV)/bin/vib-estimator survey out/fleet --baseline out/fleet/day_00 --alarm-rel 0.0025 \
		--out out/fleet_survey.csv --plot out/fleet_trend.png

# 40 operational (ambient) days of a 5 Hz mode, drifting down 0.2 %/day from day 30, against day 0
survey-ambient: setup
	$(VENV)/bin/python scripts/make_fleet.py --out out/fleet_ambient --excitation ambient
	$(VENV)/bin/vib-estimator survey out/fleet_ambient --excitation ambient \
		--baseline out/fleet_ambient/day_00 --alarm-rel 0.0025 \
		--out out/fleet_ambient_survey.csv --plot out/fleet_ambient_trend.png

# 160 ambient days of a two-mode structure whose frequencies follow the temperature (-0.2 %/degC,
# +-10 degC), stiffness 1 % lower from day 130; baseline learned from the first 80 (docs/health.md)
survey-temperature: setup
	$(VENV)/bin/python scripts/make_fleet.py --temperature --out out/fleet_temperature
	$(VENV)/bin/vib-estimator survey out/fleet_temperature --topic /accel --excitation ambient \
		--covariates /temperature:temperature --baseline-records 80 \
		--save-baseline out/fleet_temperature_baseline.yaml \
		--out out/fleet_temperature_survey.jsonl --plot out/fleet_temperature_health.png

clean:
	rm -rf $(VENV) $(JAZZY) build install log out *.egg-info
