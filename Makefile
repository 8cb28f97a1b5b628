# ArchaeoOrtho - developer and user entry points.  Every target installs what it needs.
SHELL := /bin/bash
ROOT := $(CURDIR)
VENV ?= $(ROOT)/.venv
PY := $(VENV)/bin/python
SYSPY := /usr/bin/python3
BUILD := $(ROOT)/build
PLUGINS := $(BUILD)/qgis-plugins
QGIS_CONFIG := $(BUILD)/qgis-profile
SUDO := $(shell [ "$$(id -u)" = 0 ] || echo sudo)
# proj-bin: in a venv Debian's pyproj finds its PROJ data through the `proj` executable (sys.prefix is the venv)
APT_PACKAGES := qgis python3-qgis qgis-providers python3-gdal python3-numpy python3-scipy \
                python3-matplotlib python3-venv python3-pip qttools5-dev-tools pyqt5-dev-tools xvfb xauth zip \
                chromium proj-bin
QGIS_PROCESS := $(shell command -v qgis_process.bin || command -v qgis_process || echo /usr/bin/qgis_process.bin)
PYTEST_ARGS ?=
ARGS ?=

# qgis_process and tests see the venv's packages, the plugin and a private QGIS profile
export QT_QPA_PLATFORM ?= offscreen
export QGIS_PLUGINPATH := $(PLUGINS)
PROCESS_ENV = PYTHONPATH="$$($(PY) -c 'import sysconfig; print(sysconfig.get_paths()["purelib"])'):$$PYTHONPATH" \
              QGIS_CUSTOM_CONFIG_PATH=$(QGIS_CONFIG) QGIS_PLUGINPATH=$(PLUGINS) QT_QPA_PLATFORM=offscreen

.PHONY: help setup apt venv plugin-link node-tools demo test test-fast test-qgis340 test-qgis344 process package lint transup transcompile bench clean FORCE

help:
	@echo "make setup | demo | test [PYTEST_ARGS=...] | test-fast | test-qgis340 | test-qgis344 [PYTEST_ARGS=...] | process ARGS='...' | package | lint | transup | transcompile | bench"

apt: $(BUILD)/.apt-stamp
$(BUILD)/.apt-stamp: Makefile
	@mkdir -p $(BUILD)
	@if ! dpkg -s $(APT_PACKAGES) >/dev/null 2>&1; then \
	  echo "Installing Debian packages: $(APT_PACKAGES)" >&2; \
	  $(SUDO) apt-get update -q >&2 && \
	  DEBIAN_FRONTEND=noninteractive $(SUDO) apt-get install -y -q $(APT_PACKAGES) >&2; \
	fi
	@touch $@

# The venv keeps the system NumPy, whatever its major version (1.24 on Debian 12, 2.x on Debian 13): the system
# GDAL/QGIS bindings are built against it.  Every pip install gets this constraints file, so nothing replaces it.
CONSTRAINTS := $(BUILD)/constraints.txt
$(CONSTRAINTS): $(BUILD)/.apt-stamp FORCE
	@$(SYSPY) -c "import numpy; print('numpy==' + numpy.__version__)" >$@.new
	@cmp -s $@.new $@ && rm -f $@.new || mv -f $@.new $@

venv: $(VENV)/.stamp
$(VENV)/.stamp: requirements.txt requirements-dev.txt requirements-optional.txt $(CONSTRAINTS)
	@test -x $(PY) || $(SYSPY) -m venv --system-site-packages $(VENV)
	@echo "Installing Python packages into $(VENV) ($$(cat $(CONSTRAINTS)))" >&2
	@$(PY) -m pip install -q --disable-pip-version-check -c $(CONSTRAINTS) -r requirements-dev.txt >&2
	@$(PY) -m pip install -q --disable-pip-version-check --no-deps --ignore-requires-python -c $(CONSTRAINTS) \
	  -r requirements-optional.txt >&2
	@$(PY) -c "import numpy, pycolmap, cv2; from osgeo import gdal_array; import qgis.core; \
	  assert 'numpy==' + numpy.__version__ == '$$(cat $(CONSTRAINTS))', numpy.__file__; \
	  print('venv ok: numpy', numpy.__version__, 'pycolmap', pycolmap.__version__, 'cv2', cv2.__version__, \
	        'qgis', qgis.core.Qgis.QGIS_VERSION)" >&2
	@touch $@

plugin-link: $(PLUGINS)/archaeoortho
$(PLUGINS)/archaeoortho:
	@mkdir -p $(PLUGINS) $(QGIS_CONFIG)
	@ln -sfn $(ROOT) $@

setup: apt venv plugin-link transcompile
	@$(PROCESS_ENV) $(QGIS_PROCESS) plugins enable archaeoortho >$(BUILD)/plugins-enable.log 2>&1 \
	  || grep -q "already enabled" $(BUILD)/plugins-enable.log \
	  || echo "warning: 'qgis_process plugins enable archaeoortho' failed, see $(BUILD)/plugins-enable.log" >&2
	@echo "setup done: $(PY), plugin linked at $(PLUGINS)/archaeoortho, qgis_process = $(QGIS_PROCESS)" >&2

process: setup
	@$(PROCESS_ENV) $(QGIS_PROCESS) $(ARGS)

test: setup
	@if command -v npm >/dev/null 2>&1; then $(MAKE) -s node-tools || echo "warning: 'make node-tools' failed: the glTF validator test is skipped" >&2; fi
	QGIS_PROCESS=$(QGIS_PROCESS) QGIS_CUSTOM_CONFIG_PATH=$(QGIS_CONFIG) $(PY) -m pytest $(PYTEST_ARGS)

# The Khronos glTF validator (npm gltf-validator, pure JavaScript, ~0.4 MB) for tests/test_model_tiles.py, into
# build/node (never global; installed once): `make test` runs this where npm exists, the test skips where not.
# (CesiumGS's 3d-tiles-validator could not be installed here, the registry answered 404: the test checks the
# tileset's structure itself, and runs build/node's 3d-tiles-validator where one was installed.)
NODE_TOOLS := $(BUILD)/node/node_modules/gltf-validator/package.json
node-tools: $(NODE_TOOLS)
$(NODE_TOOLS):
	@mkdir -p $(BUILD)/node
	@cd $(BUILD)/node && { [ -f package.json ] || echo '{"private": true}' >package.json; } && \
	  npm install --no-audit --no-fund --ignore-scripts --loglevel=error gltf-validator@2.0.0-dev.3.10 >&2

# The edit-test loop: the tests every CI leg runs (tests/legs.py) less those marked slow and the costliest others
# (tests/legs.py EDIT_LOOP_LEAVES_OUT), on both cores
test-fast: setup
	QGIS_PROCESS=$(QGIS_PROCESS) QGIS_CUSTOM_CONFIG_PATH=$(QGIS_CONFIG) $(PY) -m pytest -q -n 2 --dist loadfile \
	  -m "fast and not slow" $(PYTEST_ARGS)

# The same `make test` in a cached Debian chroot (root or sudo; see the script): QGIS 3.40 / Python 3.13 / NumPy 2
# (Debian 13), QGIS 3.44 / Python 3.14 (Debian sid)
test-qgis340:
	APT_PACKAGES="$(APT_PACKAGES)" PYTEST_ARGS="$(PYTEST_ARGS)" LEG=qgis340 SUITE=trixie ci/qgis-chroot.sh
test-qgis344:
	APT_PACKAGES="$(APT_PACKAGES)" PYTEST_ARGS="$(PYTEST_ARGS)" LEG=qgis344 SUITE=sid ci/qgis-chroot.sh

demo: setup
	$(PY) sample/demo.py --qgis-process "$(QGIS_PROCESS)" --build $(BUILD)

bench: setup
	@dpkg -s colmap >/dev/null 2>&1 || (DEBIAN_FRONTEND=noninteractive $(SUDO) apt-get install -y -q colmap)
	$(PY) benchmarks/align.py $(ARGS)

lint: venv
	$(VENV)/bin/ruff check .
	$(VENV)/bin/flake8 .

I18N_SOURCES := $(shell ls *.py processing_provider/*.py qgisio/*.py ui/*.py 2>/dev/null)
transup: apt
	python3 i18n/make_catalog.py && python3 i18n/update_ts.py -noobsolete

transcompile: apt
	@for ts in i18n/*.ts; do [ -e "$$ts" ] && lrelease -silent "$$ts" -qm "$${ts%.ts}.qm" || true; done

package: transcompile
	@rm -rf $(BUILD)/package && mkdir -p $(BUILD)/package/archaeoortho dist
	@git ls-files -co --exclude-standard | grep -vE '^(tests/|benchmarks/|sample/|docs/|ci/|\.ci/|\.git|\.flake8|Makefile|requirements-dev|pytest\.ini|ruff\.toml|setup\.cfg)' \
	  | while read f; do [ -f "$$f" ] && install -D -m 644 "$$f" "$(BUILD)/package/archaeoortho/$$f"; done
	@cp i18n/*.qm $(BUILD)/package/archaeoortho/i18n/ 2>/dev/null || true
	@cd $(BUILD)/package && rm -f $(ROOT)/dist/archaeoortho.zip && zip -qr $(ROOT)/dist/archaeoortho.zip archaeoortho
	@echo "dist/archaeoortho.zip: $$(unzip -l dist/archaeoortho.zip | tail -1)"

clean:
	rm -rf $(BUILD) dist .pytest_cache
