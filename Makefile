# wetdem — build, test, demo, validation, benchmarks.
#   make          library (static + shared) and the wetdem CLI in build/
#   make test     build and run every unit test (installs missing Debian packages first)
#   make check    everything CI checks: tests under ASan+UBSan (built by GCC and by clang),
#                 symbol prefixes, docs freshness, C layout (clang-format)
#   make demo     the built-in default scenario
#   make validate long validation sweeps and figures (docs/validation.md)
#   make bench    benchmarks with ratios against baselines measured in the same run
#   make figures  redraw the figures from the CSV in out/validate (no new simulations)
#   make fuzz     fuzz scenario files, checkpoints, tracked dots, fit data and command lines
#                 (libFuzzer, clang, ASan and UBSan); FUZZ_SECONDS per target, 120 by default
#   make install  the header, both libraries, wetdem.pc, the CLI, examples and docs under
#                 PREFIX (/usr/local), staged under DESTDIR if set; make uninstall removes them

# (make's own default is cc; a CC from the command line or the environment is kept)
ifeq ($(origin CC),default)
CC       = gcc
endif
BUILD   ?= build
PYTHON  ?= /usr/bin/python3
CSTD     = -std=c11 -D_DEFAULT_SOURCE
WARN     = -Wall -Wextra -Wpedantic -Wshadow -Werror
OPT     ?= -O2
# -ffp-contract=off: no fused multiply-adds, so results do not depend on the instruction set;
# -fno-math-errno: sqrt compiles to the instruction alone (it is correctly rounded either way;
# nothing here reads errno after a math function)
CFLAGS_ALL = $(CSTD) $(WARN) $(OPT) -g -fPIC -fvisibility=hidden -ffp-contract=off \
             -fno-math-errno -fopenmp -Iinclude -Isrc $(EXTRA_CFLAGS) $(CPPFLAGS) $(CFLAGS)
LDLIBS   = -lsundials_cvode -lsundials_nvecserial -lgsl -lgslcblas -linih -lm -fopenmp
VERSION := $(shell sed -n 's/^\#define WETDEM_VERSION "\(.*\)"/\1/p' include/wetdem.h)
GIT_HASH := $(shell git rev-parse --short HEAD 2>/dev/null || echo unknown)

# The shared library's name carries MAJOR.MINOR while the major version is 0 (a 0.x minor
# release may change the ABI; from 1.0 the major alone).
SOVERSION := $(if $(filter 0.%,$(VERSION)),$(basename $(VERSION)),$(firstword $(subst ., ,$(VERSION))))
SONAME   = libwetdem.so.$(SOVERSION)

LIB_SRC  = $(sort $(wildcard src/*.c))
LIB_OBJ  = $(patsubst src/%.c,$(BUILD)/obj/%.o,$(LIB_SRC))
CLI_SRC  = $(sort $(wildcard cli/*.c))
CLI_OBJ  = $(patsubst cli/%.c,$(BUILD)/cli/%.o,$(CLI_SRC))
TEST_SRC = $(sort $(wildcard tests/test_*.c))
TEST_BIN = $(patsubst tests/%.c,$(BUILD)/tests/%,$(TEST_SRC))
EX_SRC   = $(sort $(wildcard examples/*/main.c))
EX_BIN   = $(patsubst examples/%/main.c,$(BUILD)/examples/%,$(EX_SRC))

.PHONY: install uninstall all deps test check san test-san test-san-clang demo validate paraview bench figures docs clean \
        format check-format check-prefix check-docs examples fuzz fuzz-build

all: deps $(BUILD)/libwetdem.a $(BUILD)/libwetdem.so $(BUILD)/wetdem

deps:
	@scripts/install-deps build

$(BUILD)/obj/%.o: src/%.c include/wetdem.h $(wildcard src/*.h) $(BUILD)/flags.stamp
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_ALL) -c $< -o $@

# Rebuild everything when the compiler flags change. (After the dependencies are in place:
# every compile waits for it, also under make -j.)
$(BUILD)/flags.stamp: FORCE | deps
	@mkdir -p $(dir $@)
	@echo '$(CC) $(CFLAGS_ALL)' | cmp -s - $@ || echo '$(CC) $(CFLAGS_ALL)' > $@

# The CLI prints the git hash: rebuild its objects when the hash changes.
$(BUILD)/version.stamp: FORCE
	@mkdir -p $(dir $@)
	@echo '$(GIT_HASH)' | cmp -s - $@ || echo '$(GIT_HASH)' > $@

FORCE:

$(BUILD)/cli/%.o: cli/%.c include/wetdem.h $(wildcard cli/*.h) $(BUILD)/version.stamp \
                  $(BUILD)/flags.stamp
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_ALL) -DWETDEM_GIT_HASH='"$(GIT_HASH)"' -c $< -o $@

$(BUILD)/libwetdem.a: $(LIB_OBJ)
	@rm -f $@
	ar rcs $@ $^

$(BUILD)/libwetdem.so: $(LIB_OBJ)
	$(CC) -shared -Wl,-soname,$(SONAME) $(LDFLAGS) -o $@ $^ $(LDLIBS)
	@ln -sf libwetdem.so $(BUILD)/$(SONAME)

$(BUILD)/wetdem: $(CLI_OBJ) $(BUILD)/libwetdem.a
	$(CC) $(LDFLAGS) -o $@ $(CLI_OBJ) $(BUILD)/libwetdem.a $(LDLIBS)

$(BUILD)/tests/%: tests/%.c $(wildcard tests/*.h) $(BUILD)/libwetdem.a $(BUILD)/flags.stamp
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_ALL) $(LDFLAGS) -Itests -o $@ $< $(BUILD)/libwetdem.a $(LDLIBS) -lcmocka

# The allocation-failure test fails the library's allocations through wrappers of its own:
# of the C allocator, and of the SUNDIALS and GSL constructors the library calls (the same
# functions as tests/alloc_fallible.h wraps).
ALLOC_WRAP = -Wl,--wrap=malloc,--wrap=calloc,--wrap=realloc,--wrap=strdup,--wrap=free \
  -Wl,--wrap=SUNContext_Create,--wrap=N_VNew_Serial,--wrap=CVodeCreate,--wrap=CVodeInit \
  -Wl,--wrap=CVodeRootInit,--wrap=SUNDenseMatrix,--wrap=SUNLinSol_Dense \
  -Wl,--wrap=CVodeSetLinearSolver,--wrap=SUNNonlinSol_FixedPoint,--wrap=gsl_rng_alloc \
  -Wl,--wrap=gsl_matrix_alloc,--wrap=gsl_matrix_calloc,--wrap=gsl_vector_alloc \
  -Wl,--wrap=gsl_multifit_nlinear_alloc,--wrap=gsl_integration_glfixed_table_alloc
$(BUILD)/tests/test_alloc_failure: tests/test_alloc_failure.c $(wildcard tests/*.h) \
                                   $(BUILD)/libwetdem.a $(BUILD)/flags.stamp
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_ALL) $(LDFLAGS) $(ALLOC_WRAP) -Itests -o $@ $< $(BUILD)/libwetdem.a \
	  $(LDLIBS) -lcmocka

# The CLI linked with the same wrappers, the allocation to fail named by an environment variable
# (tests/cli_alloc_wrap.c), for tests/test_cli_alloc_failure.sh. It runs in the sanitizer
# builds too: --wrap redirects only the calls these objects make, and __real_malloc is the
# sanitizer's malloc (LeakSanitizer then also checks the blocks libc allocated for them).
$(BUILD)/tests/wetdem_alloc_fail: tests/cli_alloc_wrap.c tests/alloc_fallible.h $(CLI_OBJ) \
                                  $(BUILD)/libwetdem.a \
                                  $(BUILD)/flags.stamp
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_ALL) $(LDFLAGS) $(ALLOC_WRAP) -o $@ tests/cli_alloc_wrap.c $(CLI_OBJ) \
	  $(BUILD)/libwetdem.a $(LDLIBS)

$(BUILD)/examples/%: examples/%/main.c $(BUILD)/libwetdem.a $(BUILD)/flags.stamp
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_ALL) $(LDFLAGS) -o $@ $< $(BUILD)/libwetdem.a $(LDLIBS)

examples: $(EX_BIN)

test: all $(TEST_BIN) $(EX_BIN) $(BUILD)/tests/wetdem_alloc_fail
	@WETDEM_CLI='$(abspath $(BUILD)/wetdem)' CC='$(CC)' WETDEM_BUILD='$(BUILD)' \
	  WETDEM_CLI_ALLOC_FAIL='$(abspath $(BUILD)/tests/wetdem_alloc_fail)' \
	  WETDEM_EXTRA_CFLAGS='$(EXTRA_CFLAGS)' tests/run-tests $(TEST_BIN) $(EX_BIN) \
	  tests/test_install_deps.sh tests/test_install.sh tests/test_cli_alloc_failure.sh \
	  tests/test_build_without_openmp.sh

# Tests again under AddressSanitizer + UndefinedBehaviorSanitizer, in a separate build tree,
# built by GCC (test-san) and by clang (test-san-clang: its UBSan also reports pointer
# arithmetic on NULL, which GCC's does not look for).
# ASAN_OPTIONS intercept_tls_get_addr=0: the sanitizers' runtime of GCC 12 and clang 14 takes a
# block of dynamic TLS whose address falls on one offset in its page for glibc 2.19's layout and
# reads a bogus range from it, so that LeakSanitizer's scan at exit crashed ("Tracer caught
# signal 11") in about one run of test_many_force in five (google/sanitizers issue 1322). The
# library keeps no allocation reachable only from dynamic TLS, so nothing is lost to the scan.
SAN_ENV = ASAN_OPTIONS="$${ASAN_OPTIONS:+$$ASAN_OPTIONS:}intercept_tls_get_addr=0"
SAN = -fsanitize=address,undefined,float-cast-overflow
SAN_CFLAGS = $(SAN) -fno-sanitize-recover=all -fno-omit-frame-pointer
test-san:
	$(SAN_ENV) $(MAKE) test BUILD=build-san OPT=-O1 EXTRA_CFLAGS="$(SAN_CFLAGS)" \
	  LDLIBS="$(LDLIBS) $(SAN)"

test-san-clang:
	@scripts/install-deps fuzz
	$(SAN_ENV) $(MAKE) test BUILD=build-san-clang CC=clang OPT=-O1 EXTRA_CFLAGS="$(SAN_CFLAGS)" \
	  LDLIBS="$(LDLIBS) $(SAN)"

check-prefix: all
	@tools/check-prefix $(BUILD)

check-docs: all
	@$(BUILD)/wetdem docs-models > $(BUILD)/models.md && diff -u docs/models.md $(BUILD)/models.md \
	  || { echo "docs/models.md is stale: run 'make docs'"; exit 1; }
	@$(BUILD)/wetdem docs-cli > $(BUILD)/cli.md && diff -u docs/cli.md $(BUILD)/cli.md \
	  || { echo "docs/cli.md is stale: run 'make docs'"; exit 1; }

# Layout of every C file against .clang-format (clang-format 14, installed when missing).
check-format:
	@scripts/install-deps check
	@clang-format --dry-run -Werror src/*.c src/*.h include/*.h cli/*.c cli/*.h tests/*.c \
	  tests/*.h tests/fuzz/*.c tests/fuzz/*.h examples/*/main.c bench/*.c && echo "check-format: ok"

check: test test-san test-san-clang check-prefix check-docs check-format

docs: all
	$(BUILD)/wetdem docs-models > docs/models.md
	$(BUILD)/wetdem docs-cli > docs/cli.md

demo: all
	@scripts/install-deps figures
	@scripts/demo $(BUILD)/wetdem

validate: all
	@scripts/install-deps validate
	@scripts/validate $(BUILD)/wetdem

figures:
	@scripts/install-deps figures
	@for f in figures/*.py; do $(PYTHON) $$f || exit 1; done

# ParaView itself opens the many-particle output and renders a figure (installs ParaView,
# about 440 MB, when missing; not part of validate for that reason).
paraview: all
	@scripts/install-deps paraview
	@scripts/paraview $(BUILD)/wetdem

bench: all
	@scripts/install-deps bench
	@scripts/bench $(BUILD)/wetdem

# Fuzzing, in a build tree of its own: scenario files (every engine, as `run --check` reads
# them), checkpoints, the dots CSV of `track`, the data CSV of `fit` and the spheres files of
# [read.NAME], as any bytes
# (tests/fuzz/, scripts/fuzz; README, "make fuzz").
FUZZ_SECONDS ?= 120
FUZZ_TARGETS = fuzz_scenario fuzz_checkpoint fuzz_track fuzz_fit_data fuzz_args fuzz_sphere_file

fuzz:
	@scripts/install-deps fuzz
	@$(MAKE) --no-print-directory fuzz-build BUILD=build-fuzz CC=clang OPT=-O1 \
	  EXTRA_CFLAGS="$(SAN_CFLAGS) -fsanitize=fuzzer-no-link"
	@scripts/fuzz build-fuzz $(FUZZ_SECONDS) $(FUZZ_TARGETS)

fuzz-build: $(patsubst %,$(BUILD)/fuzz/%,$(FUZZ_TARGETS))

# The CLI's main() as wetdem_cli_main, for the scenario target.
$(BUILD)/fuzz/cli_main.o: cli/main.c include/wetdem.h $(wildcard cli/*.h) $(BUILD)/version.stamp \
                          $(BUILD)/flags.stamp
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_ALL) -DWETDEM_GIT_HASH='"$(GIT_HASH)"' -Dmain=wetdem_cli_main -c $< -o $@

# The CLI's objects without its main(), and the library.
FUZZ_LINK = $(filter-out $(BUILD)/cli/main.o,$(CLI_OBJ)) $(BUILD)/fuzz/cli_main.o \
            $(BUILD)/libwetdem.a

$(BUILD)/fuzz/%: tests/fuzz/%.c $(wildcard tests/fuzz/*.h) $(FUZZ_LINK)
	$(CC) $(CFLAGS_ALL) -fsanitize=fuzzer -o $@ $< $(FUZZ_LINK) $(LDLIBS) $(SAN_CFLAGS)

format:
	clang-format -i src/*.c src/*.h include/*.h cli/*.c cli/*.h tests/*.c tests/*.h examples/*/main.c \
	  bench/*.c tests/fuzz/*.c tests/fuzz/*.h

# Installation. PREFIX is written into wetdem.pc; DESTDIR only stages the files (packaging).
# The CLI links the static library, so it needs no library path at run time.
PREFIX     ?= /usr/local
BINDIR     ?= $(PREFIX)/bin
LIBDIR     ?= $(PREFIX)/lib
INCLUDEDIR ?= $(PREFIX)/include
DATADIR    ?= $(PREFIX)/share/wetdem
DOCDIR     ?= $(PREFIX)/share/doc/wetdem
INSTALL    ?= install
INSTALLED_FILES = $(BINDIR)/wetdem $(INCLUDEDIR)/wetdem.h $(LIBDIR)/libwetdem.a \
  $(LIBDIR)/libwetdem.so.$(VERSION) $(LIBDIR)/$(SONAME) $(LIBDIR)/libwetdem.so \
  $(LIBDIR)/pkgconfig/wetdem.pc
# (only what install put there, so that a DATADIR or DOCDIR shared with others is left)
INSTALLED_TREES = $(DATADIR)/examples $(DATADIR)/wetdem_vtk.py $(DOCDIR)/README.md \
  $(DOCDIR)/CHANGELOG.md $(DOCDIR)/docs

$(BUILD)/wetdem.pc: wetdem.pc.in include/wetdem.h FORCE
	@sed -e 's|@PREFIX@|$(PREFIX)|' -e 's|@LIBDIR@|$(patsubst $(PREFIX)/%,$${prefix}/%,$(LIBDIR))|' \
	  -e 's|@INCLUDEDIR@|$(patsubst $(PREFIX)/%,$${prefix}/%,$(INCLUDEDIR))|' \
	  -e 's|@VERSION@|$(VERSION)|' $< > $@.tmp && mv $@.tmp $@

install: all $(BUILD)/wetdem.pc
	$(INSTALL) -d '$(DESTDIR)$(BINDIR)' '$(DESTDIR)$(INCLUDEDIR)' '$(DESTDIR)$(LIBDIR)/pkgconfig' \
	  '$(DESTDIR)$(DATADIR)' '$(DESTDIR)$(DOCDIR)'
	$(INSTALL) -m 755 $(BUILD)/wetdem '$(DESTDIR)$(BINDIR)/wetdem'
	$(INSTALL) -m 644 include/wetdem.h '$(DESTDIR)$(INCLUDEDIR)/wetdem.h'
	$(INSTALL) -m 644 $(BUILD)/libwetdem.a '$(DESTDIR)$(LIBDIR)/libwetdem.a'
	$(INSTALL) -m 755 $(BUILD)/libwetdem.so '$(DESTDIR)$(LIBDIR)/libwetdem.so.$(VERSION)'
	ln -sf libwetdem.so.$(VERSION) '$(DESTDIR)$(LIBDIR)/$(SONAME)'
	ln -sf $(SONAME) '$(DESTDIR)$(LIBDIR)/libwetdem.so'
	$(INSTALL) -m 644 $(BUILD)/wetdem.pc '$(DESTDIR)$(LIBDIR)/pkgconfig/wetdem.pc'
	cp -R examples '$(DESTDIR)$(DATADIR)/'
	$(INSTALL) -m 644 tools/wetdem_vtk.py '$(DESTDIR)$(DATADIR)/wetdem_vtk.py'
	cp -R README.md CHANGELOG.md docs '$(DESTDIR)$(DOCDIR)/'

uninstall:
	rm -f $(foreach f,$(INSTALLED_FILES),'$(DESTDIR)$(f)')
	rm -rf $(foreach d,$(INSTALLED_TREES),'$(DESTDIR)$(d)')
	-rmdir '$(DESTDIR)$(DATADIR)' '$(DESTDIR)$(DOCDIR)' 2>/dev/null || true

clean:
	rm -rf build build-san build-san-clang build-fuzz
