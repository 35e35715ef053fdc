# fdsusp build. Uses PETSc's own make variables (compilers, flags, include and link lines).
#   make            build bin/fdsusp, bin/fdsusp-pack, bin/pairtraj and the unit-test programs (optimised)
#   make debug      the same in bin/debug/ with bounds checks and floating-point traps
#   make check      build and run the whole test suite; last line "N passed, N failed"
#                   (RANKS=3: the tests' parallel runs on 3 ranks instead of 2; RANKS=1: on one)
#   make install    programs, lubrication tables, decks, docs and the Python package under PREFIX
#                   (default /usr/local)
#   make run        run input/demo.nml on 2 ranks
#   make bench      timings recorded in doc/BENCHMARKS.md
#   make extremes   the extreme scenes of input/extremes in full (doc/VALIDATION.md §6)
#   make tradeoff   speed against accuracy, one knob at a time (doc/BENCHMARKS.md §9)
#   make pair-dns   the paper's pair test in the DNS against pairtraj (doc/VALIDATION.md §4.4)
# PETSC_DIR defaults to Debian's petsc-dev; set it to use a cluster's PETSc (3.18, real, double).

SHELL := /bin/bash
DEFAULT_PETSC_DIR := /usr/lib/petsc
PETSC_DIR ?= $(DEFAULT_PETSC_DIR)
export PETSC_DIR
# Open MPI refuses to run as root without these (CI and containers run as root).
export OMPI_ALLOW_RUN_AS_ROOT := 1
export OMPI_ALLOW_RUN_AS_ROOT_CONFIRM := 1

ifeq ($(wildcard $(PETSC_DIR)/lib/petsc/conf/variables),)
  ifeq ($(PETSC_DIR),$(DEFAULT_PETSC_DIR))
    $(info PETSc not found in $(PETSC_DIR): running scripts/install-deps)
    INSTALL_STATUS := $(shell bash scripts/install-deps 1>&2; echo $$?)
    ifneq ($(INSTALL_STATUS),0)
      $(error scripts/install-deps failed (status $(INSTALL_STATUS)))
    endif
  else
    $(error PETSC_DIR=$(PETSC_DIR) holds no PETSc (no lib/petsc/conf/variables))
  endif
endif
include $(PETSC_DIR)/lib/petsc/conf/variables

# HDF5's Fortran API (series files); PETSc's link line already holds the C library and its path.
HDF5_FC_LIB ?= -lhdf5_fortran
# FFTW's Fortran 2003 interface (fftw3-mpi.f03, Debian's libfftw3-dev / libfftw3-mpi-dev): the direct
# fluid solves (src/fluid/fft_solver.F90); PETSc's link line already holds -lfftw3_mpi -lfftw3.
FFTW_FC_INCLUDE ?= -I/usr/include
FDSUSP_FFTW_LIB := -lfftw3_mpi -lfftw3

MODE ?= opt
ifeq ($(MODE),debug)
  BUILD := build/debug
  BIN := bin/debug
  OPTFLAGS := -O0 -g -fcheck=all -ffpe-trap=invalid,zero,overflow -fbacktrace -finit-real=snan -DFDSUSP_DEBUG
  COPTFLAGS := -O0 -g
else
  BUILD := build/opt
  BIN := bin
  OPTFLAGS := -O2 -g -fbacktrace
  COPTFLAGS := -O2 -g
endif
WARN := -Wall -Wextra -Wno-unused-dummy-argument -Wno-compare-reals \
        -Wno-maybe-uninitialized -Wno-conversion
# the shipped lubrication tables are found from the build tree (doc/LUBRICATION.md)
TABLE_DIR := $(CURDIR)/input/lubrication
FCFLAGS_ALL := $(FC_FLAGS) $(OPTFLAGS) $(WARN) -fimplicit-none -std=f2018 -fall-intrinsics \
               -ffree-line-length-none -DFDSUSP_TABLE_DIR='"$(TABLE_DIR)"' \
               -J $(BUILD) -I $(BUILD) $(PETSC_FC_INCLUDES) $(FFTW_FC_INCLUDE)
CFLAGS_ALL := $(CC_FLAGS) $(COPTFLAGS) -Wall -Wextra $(PETSC_CC_INCLUDES)
LIBS := $(HDF5_FC_LIB) $(FDSUSP_FFTW_LIB) $(PETSC_LIB)

# Sources (doc/DESIGN.md "Source layout"): src/kernels (pure physics), src/runtime (decks, errors,
# OS services, PETSc options, timers), src/fluid, src/bodies (the particle step on the grid and in
# parallel), src/io (HDF5 files), src/programs (one file per program). Every module is linked into every program.
PROGRAM_SRC := $(wildcard src/programs/*.F90)
SRC_F90 := $(filter-out $(PROGRAM_SRC),$(wildcard src/*/*.F90))
SRC_C := $(wildcard src/*/*.c)
REF_F90 := $(wildcard ref/*.F90)
UNIT_F90 := $(wildcard tests/unit/test_*.F90)
# unit tests of the modules on PETSc, MPI, FFTW and HDF5 (fluid solvers, checkpoint, series): linked
# against the whole library, run as MPI singletons by tests/run_tests.sh (on 3 ranks by
# tests/regression/test_unit_petsc_ranks.sh)
UNIT_PETSC_F90 := $(wildcard tests/unit_petsc/test_*.F90)

# Objects mirror the sources: src/kernels/contact.F90 -> $(BUILD)/src/kernels/contact.o.
obj = $(addprefix $(BUILD)/,$(patsubst %.F90,%.o,$(patsubst %.c,%.o,$(1))))
LIB_OBJ := $(call obj,$(SRC_F90) $(SRC_C))
# The kernels use neither PETSc, MPI, HDF5 nor C (scripts/pure-modules --check enforces it). Unit
# tests link only these, so they run without PETSc.
PURE_F90 := $(wildcard src/kernels/*.F90)
PURE_OBJ := $(call obj,$(PURE_F90))
# pairtraj shares only kinds, vector algebra and the resistance modules with the solver (doc/DESIGN.md "Modules").
RESISTANCE_F90 := $(addprefix src/kernels/,kinds.F90 vector.F90 resistance_table.F90 pair_resistance.F90 \
                  pair_resistance_unequal.F90 wall_resistance.F90 resistance_blocks.F90 pair_mobility.F90)
PAIRTRAJ_OBJ := $(call obj,$(REF_F90) $(RESISTANCE_F90))
UNIT_BIN := $(patsubst tests/unit/%.F90,$(BUILD)/tests/%,$(UNIT_F90))
UNIT_PETSC_BIN := $(patsubst tests/unit_petsc/%.F90,$(BUILD)/tests/%,$(UNIT_PETSC_F90))
# pass/fail bookkeeping every unit test links (mod_unit_checks); the start the unit tests on PETSc
# share (mod_unit_start: PETSc, HDF5, a scratch directory)
UNIT_CHECKS_F90 := tests/unit/unit_checks.F90
UNIT_CHECKS_OBJ := $(call obj,$(UNIT_CHECKS_F90))
UNIT_START_F90 := tests/unit_petsc/unit_start.F90
UNIT_START_OBJ := $(call obj,$(UNIT_START_F90))

PROGRAMS := $(BIN)/fdsusp $(BIN)/fdsusp-pack $(BIN)/fdsusp-resistance $(if $(REF_F90),$(BIN)/pairtraj)

.PHONY: all debug check run bench extremes tradeoff pair-dns calibrate calibrate-mixtures clean tests-build install layout-check
all: $(PROGRAMS) $(UNIT_BIN) $(UNIT_PETSC_BIN)

debug:
	$(MAKE) MODE=debug all

$(BIN) $(BUILD)/tests:
	@mkdir -p $@

# The layout's rules (pure kernels, which folder may import which) are checked once per make,
# before anything is compiled; a violation stops the build naming the file, line and import.
layout-check:
	@python3 scripts/pure-modules --check

$(BUILD)/%.o: %.F90 | layout-check
	@mkdir -p $(@D)
	$(FC) $(FCFLAGS_ALL) -c $< -o $@
$(BUILD)/%.o: %.c | layout-check
	@mkdir -p $(@D)
	$(CC) $(CFLAGS_ALL) -c $< -o $@

$(BIN)/fdsusp: $(call obj,src/programs/main.F90) $(LIB_OBJ) | $(BIN)
	$(FC_LINKER) $(OPTFLAGS) -o $@ $^ $(LIBS)
$(BIN)/fdsusp-pack: $(call obj,src/programs/pack_main.F90) $(LIB_OBJ) | $(BIN)
	$(FC_LINKER) $(OPTFLAGS) -o $@ $^ $(LIBS)
$(BIN)/fdsusp-resistance: $(call obj,src/programs/resistance_main.F90 $(RESISTANCE_F90)) | $(BIN)
	$(FC_LINKER) $(OPTFLAGS) -o $@ $^
$(BIN)/pairtraj: $(PAIRTRAJ_OBJ) | $(BIN)
	$(FC_LINKER) $(OPTFLAGS) -o $@ $^
$(UNIT_BIN): $(BUILD)/tests/%: $(BUILD)/tests/unit/%.o $(UNIT_CHECKS_OBJ) $(PURE_OBJ) | $(BUILD)/tests
	$(FC_LINKER) $(OPTFLAGS) -o $@ $^ -llapack -lblas
$(UNIT_PETSC_BIN): $(BUILD)/tests/%: $(BUILD)/tests/unit_petsc/%.o $(UNIT_CHECKS_OBJ) $(UNIT_START_OBJ) $(LIB_OBJ) | $(BUILD)/tests
	$(FC_LINKER) $(OPTFLAGS) -o $@ $^ $(LIBS)

# Module dependencies, regenerated whenever a source changes.
$(BUILD)/deps.mk: $(SRC_F90) $(PROGRAM_SRC) $(REF_F90) $(UNIT_F90) $(UNIT_CHECKS_F90) $(UNIT_START_F90) $(UNIT_PETSC_F90) scripts/f90deps
	@mkdir -p $(@D)
	@scripts/f90deps $(BUILD) $(SRC_F90) $(PROGRAM_SRC) $(REF_F90) $(UNIT_F90) $(UNIT_CHECKS_F90) $(UNIT_START_F90) $(UNIT_PETSC_F90) > $@
-include $(BUILD)/deps.mk

NP ?= 2
MPIRUN := mpiexec --oversubscribe
# the demo suspension (input/demo.nml, ~2 min on 2 cores), then its summary recomputed from the
# series and its figures (doc/RHEOLOGY.md)
run: all
	$(MPIRUN) -n $(NP) $(BIN)/fdsusp input/demo.nml
	$(PYTHON) scripts/rheology.py out/demo --compare --plots out/demo/plots

# make install PREFIX=/path (default /usr/local): the programs in PREFIX/bin, the lubrication
# tables in PREFIX/share/fdsusp/lubrication (found there by the installed fdsusp, beside its bin/),
# the shipped decks in PREFIX/share/fdsusp/input and the documentation in PREFIX/share/doc/fdsusp;
# the Python package in PREFIX/share/fdsusp/python/fdsusp (PYTHONPATH=PREFIX/share/fdsusp/python;
# it finds the programs in PREFIX/bin) with the scripts that need only a run's output,
# PREFIX/share/fdsusp/scripts/rheology.py and series.py. (pip install -e . in a checkout instead.)
# FDSUSP_BIN=PREFIX/bin make check tests the installed programs.
PREFIX ?= /usr/local
PY_PACKAGE := $(wildcard python/fdsusp/*.py)
PY_INSTALLED_SCRIPTS := scripts/rheology.py scripts/series.py
install: all
	install -d $(PREFIX)/bin $(PREFIX)/share/fdsusp/lubrication $(PREFIX)/share/fdsusp/input \
	    $(PREFIX)/share/doc/fdsusp $(PREFIX)/share/fdsusp/python/fdsusp $(PREFIX)/share/fdsusp/scripts
	install -m 755 $(PROGRAMS) $(PREFIX)/bin
	install -m 644 input/lubrication/*.h5 $(PREFIX)/share/fdsusp/lubrication
	install -m 644 input/*.nml $(PREFIX)/share/fdsusp/input
	install -m 644 README.md doc/*.md $(PREFIX)/share/doc/fdsusp
	install -m 644 $(PY_PACKAGE) $(PREFIX)/share/fdsusp/python/fdsusp
	install -m 755 $(PY_INSTALLED_SCRIPTS) $(PREFIX)/share/fdsusp/scripts
	install -m 644 scripts/_fdsusp_path.py $(PREFIX)/share/fdsusp/scripts

# TESTS=pattern runs only the tests whose path contains pattern. RANKS=n (default 2): the rank
# count of the tests' parallel runs (tests/fdsusp_testlib.py; tests of their own counts keep them).
RANKS ?= 2
check: all
	@FDSUSP_TEST_RANKS=$(RANKS) bash tests/run_tests.sh $(BUILD)/tests $(TESTS)

bench: all
	@bash scripts/bench.sh

# The extreme scenes in full (input/extremes, 5 strains each; doc/VALIDATION.md §6)
extremes: all
	$(PYTHON) scripts/extremes.py --json out/extremes/extremes.json

# Speed against accuracy, one knob at a time: the suspension scene (error of each
# setting against the finest, CPU s per strain; doc/figures/tradeoff.png; 8 CPU minutes, 2026-11-26)
# and the pair test (resistance against exact theory, CPU s per run; doc/figures/tradeoff_pair.png,
# about 3 CPU minutes): ~6 min on 2 cores (2026-11-26). Tables in doc/BENCHMARKS.md §9.
tradeoff: all
	$(PYTHON) scripts/tradeoff_pair.py
	$(PYTHON) scripts/tradeoff.py

# The paper's pair test in the DNS (Gallier et al. 2014 §3; 20a cube, a/Delta = 5, dt = 1e-3, start
# -6a; five cases: eps_r = 0, 1e-3 and 1e-2, the rough ones also with mu_d = 0.3): the approach the
# cases share runs once on both cores (1 h), then the cases branch from it before their first
# contact, two at a time (scripts/pair_dns.py --branch; 1-1.6 h per case on 2 cores, the smooth
# pair's transit the longest). Resumable (PAIR_DNS_ARGS="--hours 1" stops each run with a
# checkpoint after an hour; the same command continues). Figures doc/figures/pair_dns_paper_*.png,
# table on stdout (doc/VALIDATION.md §4.4).
PAIR_DNS_ARGS ?=
pair-dns: all
	$(PYTHON) scripts/pair_dns.py $(PAIR_DNS_ARGS)

# Lubrication tables (doc/LUBRICATION.md): the resolved resistance measured at each a/Delta and
# written to input/lubrication/resolved_a<N>.h5. CELLS_PER_RADIUS="5" redoes one resolution; 5.6, 7
# and 10 are the larger species of the shipped mixtures (1.4 x 4, 1.4 x 5, 2 x 5).
CELLS_PER_RADIUS ?= 4 5 5.6 6 7 8 10
PYTHON := $(shell [ -x /usr/bin/python3 ] && echo /usr/bin/python3 || echo python3)
calibrate: all
	@for n in $(CELLS_PER_RADIUS); do $(PYTHON) scripts/calibrate.py $$n || exit 1; done

# The unequal pairs of the shipped mixtures (doc/LUBRICATION.md "Tables for mixtures"): N:R makes
# input/lubrication/resolved_a<N>_ratio<R>.h5 (sphere 1 at a/Delta = N, sphere 2 R times larger).
# The equal tables of the larger species (a/Delta = N R) come from make calibrate.
MIXTURE_PAIRS ?= 4:1.4 4:2 5:1.4 5:2
calibrate-mixtures: all
	@for p in $(MIXTURE_PAIRS); do $(PYTHON) scripts/calibrate.py $${p%%:*} --size-ratio $${p##*:} || exit 1; done

clean:
	rm -rf build bin
