# fdem-cl: the two commands.
#   make demo   install missing Debian packages (apt), build, run the demo case, write PNGs
#   make test   same set-up, then the whole test suite (the long validation runs excepted)
#   make validate   the long validation runs (build/fdem_validate, ctest label "validate"), then plots
BUILD ?= build
JOBS ?= $(shell nproc)
PYTHON := /usr/bin/python3
DEMO_OUT ?= out/demo

# Plots, all by tools/fdem-plot; tests/test_tools.sh runs these same flags on a sample.
PLOT := $(PYTHON) tools/fdem-plot
# Broken CE4s (black) over the first principal stress, one panel per frame of --frames.
CRACKS := field --var PS1 --cracks --cmap coolwarm
# Stress against strain from the platens' force and displacements (thickness 1 m: the
# cases leave mesh.thickness at its default).
BRAZILIAN_CURVE := stress-strain --test brazilian --load-region platen_top --support-region platen_bottom \
  --size 0.0517 --thickness 1
UCS_CURVE := stress-strain --test ucs --load-region platen_top --support-region platen_bottom \
  --size 0.1295 --width 0.0517 --thickness 1

# Breaks, events and fragments of the run in folder $(1), into $(2)events.png and
# $(2)fragments.png (extra `fdem-plot fragments` flags in $(3)), for a build whose runs
# write the events and fragments files.
FRACTURE_PLOTS = if ls $(1)/*_events.nc >/dev/null 2>&1; then $(PLOT) events $(1) -o $(2)events.png; fi && \
  if ls $(1)/*_fragments.nc >/dev/null 2>&1; then $(PLOT) fragments $(1) $(3) -o $(2)fragments.png; fi

# Debian 12 packages the build, the tests and the tools need.
DEBS := cmake g++ make pkg-config file ocl-icd-opencl-dev opencl-c-headers pocl-opencl-icd \
        libboost-dev libeigen3-dev libnetcdf-dev libtomlplusplus-dev doctest-dev gmsh libmetis-dev libopenmpi-dev openmpi-bin \
        python3-netcdf4 python3-matplotlib python3-numpy python3-xarray \
        clang libclang-rt-14-dev

.PHONY: all deps build test validate demo clean fuzz

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

# The sanitizer build and the fuzz targets (docs/fuzzing.md), with clang in $(FUZZ_BUILD):
# the reader, case and CLI suites under AddressSanitizer + UndefinedBehaviorSanitizer
# (ctest label "sanitize"), then each fuzz target's recorded crashes replayed and
# FUZZ_SECONDS of fuzzing from its seeds (label "fuzz"). .ci/run calls it after `make test`.
FUZZ_BUILD ?= build-fuzz
FUZZ_SECONDS ?= 20
fuzz: deps
	CC=clang CXX=clang++ cmake -S . -B $(FUZZ_BUILD) -DCMAKE_BUILD_TYPE=Release -DFDEM_FUZZ=ON -DFDEM_MPI=OFF
	cmake --build $(FUZZ_BUILD) -j $(JOBS) --target fdem fdem_fast_tests fuzz_all
	cd $(FUZZ_BUILD) && ctest -L sanitize --output-on-failure
	cd $(FUZZ_BUILD) && FDEM_FUZZ_SECONDS=$(FUZZ_SECONDS) ctest -L fuzz --output-on-failure

# The long validation runs: build/fdem_validate, the table of validation/runs.cpp, through
# its ctest entry (label "validate"; hours on a CPU). It writes every run under
# $(BUILD)/validate/ (never into the source tree), with the figures in summary.md; the
# plots go beside them.
VALIDATE_OUT = $(BUILD)/validate
validate: build
	cd $(BUILD) && ctest -L validate --verbose
	$(PLOT) compare kinetic_energy --ms --title "Disc impact (cases/impact)" \
	  $(VALIDATE_OUT)/impact-b1/impact_history.nc:"b = 1" $(VALIDATE_OUT)/impact-b2/impact_history.nc:"b = 2" \
	  $(VALIDATE_OUT)/impact-b5/impact_history.nc:"b = 5" $(VALIDATE_OUT)/impact-b20/impact_history.nc:"b = 20" \
	  $(VALIDATE_OUT)/impact-b30/impact_history.nc:"b = 30" $(VALIDATE_OUT)/impact-b2-pn10/impact_history.nc:"b = 2, P_n = 10 GPa" \
	  $(VALIDATE_OUT)/impact-b2-T1MPa/impact_history.nc:"b = 2, T = 1 MPa" -o $(VALIDATE_OUT)/impact_kinetic_energy.png
	$(PLOT) $(BRAZILIAN_CURVE) $(VALIDATE_OUT)/brazilian/brazilian_history.nc -o $(VALIDATE_OUT)/brazilian_stress_strain.png
	$(PLOT) $(CRACKS) $(VALIDATE_OUT)/brazilian/brazilian.exo --frames 2 3 5 --range -5 2 -o $(VALIDATE_OUT)/brazilian_cracks.png
	$(PLOT) $(UCS_CURVE) $(VALIDATE_OUT)/ucs/ucs_history.nc -o $(VALIDATE_OUT)/ucs_stress_strain.png
	$(PLOT) $(CRACKS) $(VALIDATE_OUT)/blasting/blasting.exo --frames 2 6 9 13 --range -20 10 \
	  -o $(VALIDATE_OUT)/blasting_absorbing_cracks.png
	$(PLOT) $(CRACKS) $(VALIDATE_OUT)/blasting-free/blasting-free.exo --frames 2 6 9 13 --range -20 10 \
	  -o $(VALIDATE_OUT)/blasting_free_cracks.png
	for f in 50 10 1; do $(PLOT) $(CRACKS) $(VALIDATE_OUT)/wave-penalty-$${f}E/wave-penalty.exo --frames 3 \
	  --range -20 10 -o $(VALIDATE_OUT)/wave_penalty_$${f}E_900us.png || exit 1; done
	for run in brazilian ucs; do $(call FRACTURE_PLOTS,$(VALIDATE_OUT)/$$run,$(VALIDATE_OUT)/$${run}_,) || exit 1; done
	for run in blasting blasting-free; do $(call FRACTURE_PLOTS,$(VALIDATE_OUT)/$$run,$(VALIDATE_OUT)/$${run}_,--without-largest) || exit 1; done
	$(PYTHON) cases/tunnel-rockmass/figures/plot.py $(VALIDATE_OUT)/tunnel-rockmass $(VALIDATE_OUT)/tunnel-rockmass
	@cat $(VALIDATE_OUT)/wave-penalty.md
	@echo "validation output, its figures (summary.md) and plots in $(VALIDATE_OUT)/"

# The demo: the seed paper's Brazilian disc test on the default device, then the crack
# pattern before the peak, at the peak and after it, and the stress-strain curve. With a
# GPU the case's own 0.7 mm mesh (10k TRI3, 1.5 M steps, about 4 min on an H200); on a
# CPU a 3 mm mesh (a few minutes on 2 cores) so that the demo finishes.
demo: build
	@if $(BUILD)/fdem devices | grep -q '\[GPU\]'; then set -- ; else \
	  echo "no GPU found: running the Brazilian disc on a coarse 3 mm mesh"; set -- --set mesh.size=3e-3; fi; \
	$(BUILD)/fdem run cases/brazilian/case.toml --set output.dir=$(DEMO_OUT) --set output.frames=16 "$$@"
	$(PLOT) $(BRAZILIAN_CURVE) $(DEMO_OUT)/brazilian_history.nc -o $(DEMO_OUT)/brazilian_stress_strain.png
	$(PLOT) $(CRACKS) $(DEMO_OUT)/brazilian.exo --frames 7 8 11 --range -5 2 -o $(DEMO_OUT)/brazilian_cracks.png
	$(call FRACTURE_PLOTS,$(DEMO_OUT),$(DEMO_OUT)/brazilian_)
	@echo "demo output in $(DEMO_OUT)/: brazilian.exo (open in ParaView), brazilian_history.nc, *.png"

clean:
	rm -rf $(BUILD)
