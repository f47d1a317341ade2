# twodisk_ros — every command a user or CI needs. Each target creates the venv it uses.
PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
# DDS discovery stays on this machine; each target may override the domain id.
export ROS_AUTOMATIC_DISCOVERY_RANGE := LOCALHOST
export ROS_DOMAIN_ID ?= 73
export PYTHONPATH := $(CURDIR)$(if $(PYTHONPATH),:$(PYTHONPATH))
export MPLBACKEND := Agg
# where make demo writes (a test runs it into a temporary directory), the simulated seconds
# it records and the seconds of it the GIF shows
OUT ?= out
DEMO_SECONDS ?= 20.0
GIF_SECONDS ?= 6

.PHONY: venv foxglove-readers chromium test demo figures bench clean

venv: $(VENV)/.installed $(VENV)/.tf2_msgs

# The pinned requirements, then twodisk_ros itself (editable: the venv runs this checkout's
# code; in setuptools' "compat" mode, a path entry in a .pth file, where the default editable
# finder cost every Python process of the venv ~40 ms of CPU at start-up), so `roller`, `twodisk-inspect`, `twodisk-animate`, `twodisk-sweep`, `twodisk-view`
# and `twodisk-figures` are in .venv/bin and work from any directory; the parameter files go to
# .venv/share/twodisk_ros/config, where a colcon install puts them.
$(VENV)/.installed: requirements.txt requirements-nodeps.txt setup.py setup.cfg $(wildcard config/*)
	$(PYTHON) -m venv $(VENV)
	$(VENV)/bin/pip install --quiet --disable-pip-version-check -r requirements.txt
	$(VENV)/bin/pip install --quiet --disable-pip-version-check --no-deps -r requirements-nodeps.txt
	$(VENV)/bin/pip install --quiet --disable-pip-version-check --no-deps --no-build-isolation \
	    --use-pep517 --config-settings editable_mode=compat --editable .
	install -d $(VENV)/share/twodisk_ros/config
	install -m 644 package.xml $(VENV)/share/twodisk_ros/
	install -m 644 config/* $(VENV)/share/twodisk_ros/config/
	touch $@

# tf2_msgs/msg/TFMessage (for /tf) is not a wheel: tools/build_interfaces.py generates and
# compiles it from interfaces/tf2_msgs with the rosidl tool chain pinned in requirements.txt
# and installs it into .venv, once (needs gcc/g++ and the Python headers). On failure it says
# in one line what is missing, installs nothing and names its log, .venv/tf2_msgs-build.log.
TF2_MSGS := $(wildcard interfaces/tf2_msgs/*.xml interfaces/tf2_msgs/*.txt \
                       interfaces/tf2_msgs/msg/*.msg)
$(VENV)/.tf2_msgs: $(VENV)/.installed tools/build_interfaces.py $(TF2_MSGS)
	@$(PY) tools/build_interfaces.py --prefix $(VENV) --stamp $@ \
	    --log $(VENV)/tf2_msgs-build.log

## Foxglove's own readers (Node.js: @mcap/core, @foxglove/rosmsg2-serialization), for the tests
## that decode recordings as the Foxglove app does; versions pinned in the lock file.
foxglove-readers: tests/foxglove/node_modules/.installed

tests/foxglove/node_modules/.installed: tests/foxglove/package.json tests/foxglove/package-lock.json
	@command -v npm >/dev/null || { echo "npm not found: install Node.js 18 or later (apt-get install nodejs npm)"; exit 2; }
	cd tests/foxglove && npm ci --ignore-scripts --no-audit --no-fund --loglevel=error
	touch $@

## The page's browser tests (tests/test_explore_browser.py) use Debian's chromium; on CI
## (CI=true) it is installed when missing, elsewhere those tests skip saying how to install it.
chromium:
	@if [ "$$CI" = true ] && ! command -v chromium >/dev/null; then \
	    SUDO=$$(command -v sudo >/dev/null && [ "$$(id -u)" != 0 ] && echo sudo); \
	    $$SUDO apt-get update -qq && $$SUDO apt-get install -y -qq --no-install-recommends chromium; fi

## Run the whole test suite (what CI runs), one pytest worker per core. A test module stays
## on one worker: the modules whose nodes subscribe each use a ROS domain of their own.
## The package's bytecode is written first: the suite starts a few hundred Python processes,
## and where PYTHONDONTWRITEBYTECODE is set each would compile the package again (~0.2 s of
## CPU apiece). PYTEST_ARGS adds options (make bench passes --durations).
PYTEST_ARGS ?=
test: venv foxglove-readers chromium
	@$(PY) -m compileall -q twodisk_ros tests benchmarks tools
	$(PY) -m pytest -n auto --dist loadfile $(PYTEST_ARGS)

## The main job: record a 20 s oloid run to MCAP, check it offline, write a plot and a GIF.
demo: venv
	mkdir -p $(OUT)
	$(PY) -m twodisk_ros.roller --ros-args --params-file config/oloid.yaml \
	    -p realtime:=false -p duration:=$(DEMO_SECONDS) -p record:=$(OUT)/oloid.mcap -p overwrite:=true
	$(PY) -m twodisk_ros.inspect_mcap $(OUT)/oloid.mcap --plot $(OUT)/oloid.png --overwrite
	$(PY) -m twodisk_ros.plotting.animate_cli $(OUT)/oloid.mcap -o $(OUT)/oloid.gif \
	    --stop $(GIF_SECONDS) --fps 15 --size 480x360 --overwrite

## The paper's figures, whole cycles, the height of G, the stability map, contact forces, and
## contact_model hybrid beside MuJoCo alone (PNG; the last prints the tables of docs/physics.md).
figures: venv
	$(PY) -m twodisk_ros.plotting.figures --out docs/figures --overwrite
	$(PY) -m twodisk_ros.plotting.contact_forces --out docs/figures --overwrite
	$(PY) -m twodisk_ros.plotting.hybrid_figures --out docs/figures --overwrite

## Benchmarks: writes docs/benchmarks.md and the work-precision plot; then the page's section
## of docs/benchmarks.md (twodisk-explore in headless Chromium) and the section of
## contact_model hybrid against MuJoCo alone.
bench: venv chromium
	$(PY) benchmarks/run_all.py --overwrite
	$(PY) benchmarks/explore_rate.py
	$(PY) benchmarks/hybrid_cost.py

clean:
	rm -rf $(VENV) tests/foxglove/node_modules out build install log .pytest_cache .hypothesis twodisk_ros.egg-info
