# fdem-cl: the two commands.
#   make demo   install missing Debian packages (apt), build, run the demo case, write PNGs
#   make test   same set-up, then the whole test suite (the long validation runs excepted)
#   make validate   the long validation runs (ctest label "validate")
BUILD ?= build
JOBS ?= $(shell nproc)
PYTHON := /usr/bin/python3
DEMO_OUT ?= out/demo

# Debian 12 packages the build, the tests and the tools need.
DEBS := cmake g++ make pkg-config file ocl-icd-opencl-dev opencl-c-headers pocl-opencl-icd \
        libboost-dev libeigen3-dev libnetcdf-dev libtomlplusplus-dev doctest-dev gmsh \
        python3-netcdf4 python3-matplotlib python3-numpy

.PHONY: all deps build test validate demo clean

all: build

deps:
	@missing=$$(for p in $(DEBS); do dpkg -s $$p >/dev/null 2>&1 || printf '%s ' $$p; done); \
	if [ -n "$$missing" ]; then \
	  echo "Installing missing Debian packages: $$missing"; \
	  if [ "$$(id -u)" = 0 ]; then SUDO=""; \
	  elif command -v sudo >/dev/null 2>&1 && sudo -n true 2>/dev/null; then SUDO="sudo"; \
	  else echo "Cannot install as $$(whoami). Run:"; echo "  sudo apt-get install -y $$missing"; exit 1; fi; \
	  $$SUDO apt-get update -qq && \
	  DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -qq --no-install-recommends $$missing \
	    || { echo "apt-get failed. Run:"; echo "  sudo apt-get install -y $$missing"; exit 1; }; \
	fi

build: deps
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release
	cmake --build $(BUILD) -j $(JOBS)

# Suites run one after another: each OpenCL test already uses every core through PoCL.
test: build
	cd $(BUILD) && ctest -L unit --output-on-failure

# The long validation runs (minutes on a CPU); their output stays under out/validate/.
validate: build
	cd $(BUILD) && ctest -L validate --output-on-failure
	$(PYTHON) tools/fdem-plot compare kinetic_energy --ms --title "Disc impact (cases/impact)" \
	  out/validate/impact-b1/impact_history.nc:"b = 1" out/validate/impact-b2/impact_history.nc:"b = 2" \
	  out/validate/impact-b5/impact_history.nc:"b = 5" out/validate/impact-b20/impact_history.nc:"b = 20" \
	  out/validate/impact-b30/impact_history.nc:"b = 30" out/validate/impact-b2-pn10/impact_history.nc:"b = 2, P_n = 10 GPa" \
	  out/validate/impact-b2-T1MPa/impact_history.nc:"b = 2, T = 1 MPa" -o out/validate/impact_kinetic_energy.png
	@echo "validation output and plots in out/validate/"

# The demo: the seed paper's geostatic column (98k TRI3, 6,400 steps) on the default
# device, then a stress map and the convergence history as PNGs.
demo: build
	$(BUILD)/fdem run cases/geostatic/case.toml --set output.dir=$(DEMO_OUT)
	$(PYTHON) tools/fdem-plot field $(DEMO_OUT)/geostatic.exo --var SYY -o $(DEMO_OUT)/geostatic_SYY.png
	$(PYTHON) tools/fdem-plot field $(DEMO_OUT)/geostatic.exo --var SXX -o $(DEMO_OUT)/geostatic_SXX.png
	$(PYTHON) tools/fdem-plot history $(DEMO_OUT)/geostatic_history.nc kinetic_energy --log -o $(DEMO_OUT)/geostatic_kinetic_energy.png
	$(PYTHON) tools/fdem-plot history $(DEMO_OUT)/geostatic_history.nc unbalanced_ratio --log -o $(DEMO_OUT)/geostatic_unbalanced.png
	@echo "demo output in $(DEMO_OUT)/: geostatic.exo (open in ParaView), geostatic_history.nc, *.png"

clean:
	rm -rf $(BUILD)
