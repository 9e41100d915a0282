# phgmg — build, test, demo, bench.
#   make test      build and run every test (plain, then ASan+UBSan), compile checks
#   make demo      reproduce Section 5 of the paper into results/
#   make bench     timings into bench/results.csv
#   make examples  build the examples
#   make embedded  cross-compile the controller example for Cortex-M4F
#   make fuzz      short fuzzing run of every reader of outside data
#   make docs-check  the docs against the code (part of make test)
CC      ?= cc
CXX     ?= c++
WARN     = -Wall -Wextra -Werror -pedantic -Wshadow
CFLAGS_T = -std=c99 $(WARN) -O1 -g1
SANFLAGS = -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=all
# The sanitizer build's debug level: -g0 (reports name functions, not lines;
# line tables cost 15 % of its compile). make ASAN_G=-g1 for line numbers.
ASAN_G  ?= -g0
OPTFLAGS = -std=c99 $(WARN) -O2 -march=native
LDLIBS   = -lm

TESTSRC := $(wildcard tests/test_*.c)
BUILD    = build

.PHONY: test-mpi check-descriptor docs-check test-hello test-build test-validate test-deploy all test test-plain test-asan compile-checks test-embedded-host test-npy test-cli test-demo test-fuzz-replay demo bench examples embedded fuzz clean

all: phgmg.h examples

tests/suites.inc: $(TESTSRC)
	grep -h '^SUITE(' $(TESTSRC) | sed 's/^SUITE(\([a-z0-9_]*\)).*/SUITE_DECL(\1)/' > $@

# Each unit includes the implementation with PHGMG_STATIC; the units build in
# parallel (make test builds them with -j2).
# The files that configure the implementation are units of their own; the
# others are compiled together in tests/unity_a.c and tests/unity_b.c (one
# copy of the implementation per unit: the compiles are most of make test).
TEST_SOLO    = tests/test_reduce.c tests/test_robust.c tests/test_rsvd.c tests/test_scale.c
TEST_UNITS   = tests/run.c tests/unity_a.c tests/unity_b.c $(TEST_SOLO)
TESTOBJ      = $(patsubst tests/%.c,$(BUILD)/obj/%.o,$(TEST_UNITS))
TESTOBJ_ASAN = $(patsubst tests/%.c,$(BUILD)/obj_asan/%.o,$(TEST_UNITS))
$(BUILD)/obj/unity_%.o $(BUILD)/obj_asan/unity_%.o: $(filter-out $(TEST_SOLO),$(TESTSRC)) \
  examples/msd_models.h tests/sepfun_models.h tests/lowrank_fixture.h

$(BUILD)/obj/%.o: tests/%.c phgmg.h tests/harness.h tests/fixture_msd.h tests/suites.inc
	@mkdir -p $(BUILD)/obj
	$(CC) $(CFLAGS_T) -c -o $@ $<

$(BUILD)/obj_asan/%.o: tests/%.c phgmg.h tests/harness.h tests/fixture_msd.h tests/suites.inc
	@mkdir -p $(BUILD)/obj_asan
	$(CC) $(CFLAGS_T) -O1 $(ASAN_G) $(SANFLAGS) -c -o $@ $<

$(BUILD)/test_run: $(TESTOBJ)
	$(CC) $(CFLAGS_T) -o $@ $(TESTOBJ) $(LDLIBS)

$(BUILD)/test_run_asan: $(TESTOBJ_ASAN)
	$(CC) $(CFLAGS_T) -O1 $(ASAN_G) $(SANFLAGS) -o $@ $(TESTOBJ_ASAN) $(LDLIBS)

# After the compiles, the single-core stages run as independent jobs on both
# cores, the longest first (each job's output is printed whole when it ends --
# GNU make 4's --output-sync, left out by older makes; a failure stops make test).
SYNC = $(if $(filter output-sync,$(.FEATURES)),--output-sync=target,)
# The unit suites run once, under ASan + UBSan at -O1 with the warning flags
# (the plain runner, `make test-plain`, runs the same tests without the
# sanitizers; it is the quick one during development).
# The runs go longest first, so that both cores stay busy to the end.
test: test-build
	$(MAKE) -j2 $(SYNC) test-asan test-mpi test-demo test-cli test-embedded-host compile-checks \
	  test-fuzz-replay docs-check test-validate test-npy test-hello


# Everything make test compiles, built first on both cores (the compiles are
# most of its time); the runs below then go one after the other.
test-build: tests/suites.inc
	$(MAKE) -j2 $(BUILD)/test_run_asan $(EXAMPLES) $(BUILD)/phgmg-float $(BUILD)/npy_tool \
	  $(BUILD)/export_model_d $(BUILD)/export_model_f

# The distributed layer (PHGMG_MPI; tests/mpi/test_mpi.c, tests/mpi/test_mpi_nl.c,
# tests/mpi/test_mpi_damp.c, examples/mpi_pod.c; the distributed command line against the serial one,
# tests/mpi/check_cli_mpi.sh)
# at 1, 2, 3 and 4 ranks (4: one rank owns no rows; more ranks than cores;
# test_mpi_nl, the longest, at 4 (uneven blocks, a rank without rows, more
# ranks than cores) and test_mpi_damp at 3 (both measured at 1-4): one rank
# and the even split of 2 are covered by the others), each run's results
# compared with the one-rank
# run's; the section's compile
# checks (C99, float online scalar, C++). Skipped, with a message, without
# mpicc and mpirun (Debian: openmpi-bin libopenmpi-dev). A deadlock fails
# after 120 s (timeout). More ranks than cores: the ranks yield the core while
# they wait (mpi_yield_when_idle), so that the jobs beside them keep it. The
# programs share one compile of the implementation
# ($(BUILD)/mpi/lib.o; they are built with PHGMG_IMPLEMENTATION_ELSEWHERE).
# About 95 s.
MPICC  ?= mpicc
MPICXX ?= mpicxx
MPIRUN  = mpirun --oversubscribe --mca mpi_yield_when_idle 1 $$(if [ "$$(id -u)" = 0 ]; then echo --allow-run-as-root; fi)
test-mpi:
	@if ! command -v $(MPICC) >/dev/null 2>&1 || ! command -v mpirun >/dev/null 2>&1; then \
	  echo "test-mpi: skipped (no $(MPICC) or mpirun; Debian packages openmpi-bin libopenmpi-dev)"; exit 0; fi; \
	mkdir -p $(BUILD)/mpi && rm -f $(BUILD)/mpi/res_*.bin && \
	printf '#define PHGMG_MPI\n#define PHGMG_IMPLEMENTATION\n#include "../../phgmg.h"\nint main(void){return 0;}\n' > $(BUILD)/mpi/impl.c && \
	cp $(BUILD)/mpi/impl.c $(BUILD)/mpi/impl.cpp && \
	$(MPICC) -std=c99 $(WARN) -Wdouble-promotion -DPHGMG_REAL_FLOAT -fsyntax-only $(BUILD)/mpi/impl.c && \
	$(MPICC) -std=c99 $(WARN) -DPHGMG_NO_OFFLINE -fsyntax-only $(BUILD)/mpi/impl.c && \
	if command -v $(MPICXX) >/dev/null 2>&1; then $(MPICXX) -std=c++11 -Wall -Wextra -Werror -fsyntax-only $(BUILD)/mpi/impl.cpp; fi && \
	printf '#define PHGMG_MPI\n#define PHGMG_IMPLEMENTATION\n#include "../../phgmg.h"\n' > $(BUILD)/mpi/lib.c && \
	$(MPICC) $(CFLAGS_T) -c -o $(BUILD)/mpi/lib.o $(BUILD)/mpi/lib.c && \
	$(MPICC) $(CFLAGS_T) -DPHGMG_IMPLEMENTATION_ELSEWHERE -o $(BUILD)/test_mpi tests/mpi/test_mpi.c $(BUILD)/mpi/lib.o $(LDLIBS) && \
	$(MPICC) $(CFLAGS_T) -DPHGMG_IMPLEMENTATION_ELSEWHERE -o $(BUILD)/mpi_pod examples/mpi_pod.c $(BUILD)/mpi/lib.o $(LDLIBS) && \
	for p in 1 2 3 4; do timeout 120 $(MPIRUN) -np $$p ./$(BUILD)/test_mpi $(BUILD)/mpi || exit 1; done && \
	$(MPICC) $(CFLAGS_T) -DPHGMG_IMPLEMENTATION_ELSEWHERE -o $(BUILD)/test_mpi_stream tests/mpi/test_mpi_stream.c $(BUILD)/mpi/lib.o $(LDLIBS) && \
	for p in 1 2 3 4; do timeout 120 $(MPIRUN) -np $$p ./$(BUILD)/test_mpi_stream || exit 1; done && \
	$(MPICC) $(CFLAGS_T) -DPHGMG_IMPLEMENTATION_ELSEWHERE -o $(BUILD)/test_mpi_nl tests/mpi/test_mpi_nl.c $(BUILD)/mpi/lib.o $(LDLIBS) && \
	timeout 120 $(MPIRUN) -np 4 ./$(BUILD)/test_mpi_nl $(BUILD)/mpi && \
	$(MPICC) $(CFLAGS_T) -DPHGMG_IMPLEMENTATION_ELSEWHERE -o $(BUILD)/test_mpi_damp tests/mpi/test_mpi_damp.c $(BUILD)/mpi/lib.o $(LDLIBS) && \
	timeout 120 $(MPIRUN) -np 3 ./$(BUILD)/test_mpi_damp && \
	$(MPIRUN) -np 3 ./$(BUILD)/mpi_pod --N 3000 > $(BUILD)/mpi/example.txt && echo "test-mpi: examples/mpi_pod.c runs at 3 ranks" && \
	$(MPICC) $(CFLAGS_T) -DPHGMG_IMPLEMENTATION_ELSEWHERE -o $(BUILD)/mpi/phgmg-mpi examples/phgmg_mpi_cli.c $(BUILD)/mpi/lib.o $(LDLIBS) && \
	$(MAKE) --no-print-directory $(BUILD)/phgmg && sh tests/mpi/check_cli_mpi.sh $(BUILD)/phgmg $(BUILD)/mpi/phgmg-mpi

# The distributed command line (examples/phgmg_mpi_cli.c; manual 2.7):
#   mpirun -np P build/phgmg-mpi reduce --J-coo J.npy --R-coo R.npy --Q-coo Q.npy \
#       --B B.npy --X X.npy --method gmg-pod|sp1 --r R --out DIR
# the files of the serial `phgmg reduce`, the rows of the state spread over the
# ranks, J - R solved by the library's sparse LU replicated on every rank.
# (make test-mpi checks the same source compiled at -O1, as its other programs.)
$(BUILD)/phgmg-mpi: examples/phgmg_mpi_cli.c phgmg.h
	@mkdir -p $(BUILD)
	$(MPICC) $(OPTFLAGS) -o $@ $< $(LDLIBS)

# A real distributed solver behind the solve callback (examples/petsc_mumps.c:
# PETSc assembles J - R as MPIAIJ, MUMPS factors it) checked against the
# serial command line at 1, 2 and 4 ranks (tests/mpi/check_petsc.sh). Needs
# mpicc and PETSc with MUMPS, found by pkg-config (Debian: libpetsc-real-dev;
# another PETSc: PKG_CONFIG_PATH=$PETSC_DIR/$PETSC_ARCH/lib/pkgconfig).
# Skipped without them; not part of make test. About 10 s after the compile.
.PHONY: test-petsc
PETSC_PC = pkg-config --exists petsc 2>/dev/null && command -v $(MPICC) >/dev/null 2>&1 && command -v mpirun >/dev/null 2>&1
$(BUILD)/petsc_mumps: examples/petsc_mumps.c phgmg.h
	@if ! $(PETSC_PC); then echo "petsc_mumps: skipped (needs $(MPICC), mpirun and PETSc via pkg-config; Debian: libpetsc-real-dev)"; exit 0; fi; \
	mkdir -p $(BUILD) && echo "$(MPICC) ... -o $@ $< (PETSc: pkg-config petsc)" && \
	$(MPICC) -std=c99 $(WARN) -O2 $$(pkg-config --cflags petsc) -o $@ $< $$(pkg-config --libs petsc) $(LDLIBS)
test-petsc:
	@if ! $(PETSC_PC); then echo "test-petsc: skipped (needs $(MPICC), mpirun and PETSc via pkg-config; Debian: libpetsc-real-dev)"; exit 0; fi; \
	$(MAKE) --no-print-directory $(BUILD)/phgmg $(BUILD)/petsc_mumps && sh tests/mpi/check_petsc.sh $(BUILD)

# The documentation against the code: every public function in the manual's
# index, every CLI option in --help, README's first C block compiles and runs,
# no tracked file named '-...', no issue numbers in README.md, phgmg.h, Makefile.
docs-check: $(BUILD)/phgmg
	/usr/bin/python3 tests/docs_check.py $(BUILD)/phgmg

# The quick start of README.md (examples/hello.c): reduce and step a model.
test-hello: $(BUILD)/hello
	./$(BUILD)/hello

# `phgmg validate` and the deployment checks (tests/test_validate.sh, a few seconds).
test-validate: $(BUILD)/phgmg
	sh tests/test_validate.sh $(BUILD)/phgmg

# The deployment study at every r = 6..20 on both chains (GMG-QM with the
# validated lambda on five inputs, one and two training runs; the training-only
# validated model against GMG-POD); minutes, not part of make test.
test-deploy: $(EXAMPLES)
	@mkdir -p results/deploy
	./$(BUILD)/msd_linear --lambda auto --rmin 6 --out results/deploy
	./$(BUILD)/msd_nonlinear --lambda auto --rmin 6 --rstep 1 --out results/deploy
	./$(BUILD)/msd_linear --generalization 6,7,8,9,10,11,12,13,14,15,16,17,18,19,20 --out results/deploy
	./$(BUILD)/msd_nonlinear --generalization 6,7,8,9,10,11,12,13,14,15,16,17,18,19,20 --out results/deploy
	/usr/bin/python3 tests/check_claims.py results/deploy --full

# Replay the fuzz corpora of every reader and of the CLI's argument handling
# (clang sanitizers when available; ~15 s, mostly building the five harnesses).
test-fuzz-replay:
	sh tests/fuzz/run.sh 0

# The whole Section-5 study, then the paper's qualitative claims on its CSVs.
test-demo: demo

# Embedded path on the host: export the demo models (double and float), check
# binary and C-source exports reproduce the in-memory outputs exactly, float vs double.
# (Both link a shared compile of the implementation, double or float:
# ISO C's -ffp-contract=off keeps the numbers those of a one-file build.)
$(BUILD)/export_model_d: examples/controller/export_model.c examples/controller/controller_run.h phgmg.h examples/msd_models.h examples/morse_models.h $(BUILD)/phgmg_impl.o
	@mkdir -p $(BUILD)
	$(CC) -std=c99 $(WARN) -O1 -DPHGMG_IMPLEMENTATION_ELSEWHERE -o $@ $< $(BUILD)/phgmg_impl.o $(LDLIBS)
$(BUILD)/export_model_f: examples/controller/export_model.c examples/controller/controller_run.h phgmg.h examples/msd_models.h examples/morse_models.h $(BUILD)/phgmg_impl_f.o
	@mkdir -p $(BUILD)
	$(CC) -std=c99 $(WARN) -Wdouble-promotion -DPHGMG_REAL_FLOAT -O1 -DPHGMG_IMPLEMENTATION_ELSEWHERE -o $@ $< $(BUILD)/phgmg_impl_f.o $(LDLIBS)
$(BUILD)/phgmg_impl_f.o: phgmg.h
	@mkdir -p $(BUILD)
	@printf '#define PHGMG_IMPLEMENTATION\n#include "../phgmg.h"\n' > $(BUILD)/phgmg_impl_f.c
	$(CC) -std=c99 $(WARN) -O1 -march=native -Wdouble-promotion -DPHGMG_REAL_FLOAT -c -o $@ $(BUILD)/phgmg_impl_f.c
test-embedded-host: $(BUILD)/export_model_d $(BUILD)/export_model_f $(BUILD)/phgmg_impl.o
	sh examples/controller/check.sh $(BUILD)
	sh tests/sepfun_export.sh $(BUILD)

# Cross-compile the controller for Cortex-M4F (float and double), sizes, and a
# run under qemu-system-arm when installed.
embedded: $(BUILD)/export_model_d $(BUILD)/export_model_f
	sh examples/controller/check.sh $(BUILD)
	sh examples/controller/embedded.sh $(BUILD)

# .npy round trips against real NumPy (Debian python3-numpy, /usr/bin/python3).
$(BUILD)/npy_tool: tests/npy_tool.c phgmg.h
	@mkdir -p $(BUILD)
	$(CC) -std=c99 $(WARN) -O1 -o $@ $< $(LDLIBS)
test-npy: $(BUILD)/npy_tool
	/usr/bin/python3 tests/test_npy_numpy.py $(BUILD)/npy_tool

test-plain: $(BUILD)/test_run
	./$(BUILD)/test_run

# (allocation stacks in reports four frames deep: a tenth of the run time)
test-asan: $(BUILD)/test_run_asan
	ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:malloc_context_size=4 UBSAN_OPTIONS=print_stacktrace=1 ./$(BUILD)/test_run_asan

# The header as users build it (syntax and warnings: -fsyntax-only; the two-unit
# PHGMG_STATIC build is compiled and linked): C99, C11, C++, float online scalar, PHGMG_STATIC
# in two translation units, declarations only, offline half compiled out.
compile-checks: phgmg.h
	@mkdir -p $(BUILD)/cc
	@printf '#define PHGMG_IMPLEMENTATION\n#include "../../phgmg.h"\nint main(void){return 0;}\n' > $(BUILD)/cc/impl.c
	@cp $(BUILD)/cc/impl.c $(BUILD)/cc/impl.cpp
	@printf '#include "../../phgmg.h"\nint decl_only(void){return (int)PHGMG_OK;}\n' > $(BUILD)/cc/decl.c
	@printf '#define PHGMG_STATIC\n#define PHGMG_IMPLEMENTATION\n#include "../../phgmg.h"\nint tu2(void){return (int)PHGMG_OK;}\n' > $(BUILD)/cc/s2.c
	@printf '#define PHGMG_STATIC\n#define PHGMG_IMPLEMENTATION\n#include "../../phgmg.h"\nint tu2(void);\nint main(void){return tu2();}\n' > $(BUILD)/cc/s1.c
	$(CC) -std=c99 $(WARN) -Wdouble-promotion -fsyntax-only $(BUILD)/cc/impl.c
	$(CC) -std=c11 $(WARN) -Wdouble-promotion -fsyntax-only $(BUILD)/cc/impl.c
	$(CC) -std=c99 $(WARN) -Wdouble-promotion -DPHGMG_REAL_FLOAT -fsyntax-only $(BUILD)/cc/impl.c
	$(CC) -std=c99 $(WARN) -Wdouble-promotion -DPHGMG_REAL_FLOAT -DPHGMG_NO_OFFLINE -fsyntax-only $(BUILD)/cc/impl.c
	$(CC) -std=c99 $(WARN) -DPHGMG_NO_OFFLINE -fsyntax-only $(BUILD)/cc/impl.c
	$(CXX) -std=c++11 -Wall -Wextra -Werror -fsyntax-only $(BUILD)/cc/impl.cpp
	$(CXX) -std=c++11 -Wall -Wextra -Werror -DPHGMG_REAL_FLOAT -fsyntax-only $(BUILD)/cc/impl.cpp
	$(CC) -std=c99 $(WARN) -fsyntax-only $(BUILD)/cc/decl.c
	$(CC) -std=c99 $(WARN) $(BUILD)/cc/s1.c $(BUILD)/cc/s2.c -o $(BUILD)/cc/static2 $(LDLIBS)
	if printf 'int main(void){return 0;}\n' | $(CC) -fopenmp -x c - -o $(BUILD)/cc/omp >/dev/null 2>&1; then \
	  $(CC) -std=c99 $(WARN) -fopenmp -DPHGMG_USE_OPENMP -fsyntax-only $(BUILD)/cc/impl.c && \
	  $(CXX) -std=c++11 -Wall -Wextra -Werror -fopenmp -DPHGMG_USE_OPENMP -fsyntax-only $(BUILD)/cc/impl.cpp; fi
	if command -v clang >/dev/null 2>&1; then clang -std=c99 $(WARN) -Wdouble-promotion -fsyntax-only $(BUILD)/cc/impl.c && \
	  clang -std=c99 $(WARN) -Wdouble-promotion -DPHGMG_REAL_FLOAT -fsyntax-only $(BUILD)/cc/impl.c; fi
	@echo "compile checks passed"

EXAMPLES = $(BUILD)/hello $(BUILD)/msd_linear $(BUILD)/msd_nonlinear $(BUILD)/morse_chain $(BUILD)/phgmg $(BUILD)/linear_bases $(BUILD)/fe_bar $(BUILD)/transport_line $(BUILD)/circuit_dae $(BUILD)/damped_chain
EXHDRS   = examples/msd_models.h examples/morse_models.h examples/demo_common.h examples/svgplot.h

examples: $(EXAMPLES) $(BUILD)/phgmg-float

# the command-line reducer (examples/phgmg_cli.c) is installed as build/phgmg
$(BUILD)/phgmg: examples/phgmg_cli.c phgmg.h $(BUILD)/phgmg_impl.o
	@mkdir -p $(BUILD)
	$(CC) $(OPTFLAGS) -DPHGMG_IMPLEMENTATION_ELSEWHERE -o $@ $< $(BUILD)/phgmg_impl.o $(LDLIBS)

# The command line in a float build: the offline work stays double, the
# reduced model, simulate-rom and the exported C source are float (for
# float firmware). -O1: make test runs it on small models only (half the
# compile time of -O2).
$(BUILD)/phgmg-float: examples/phgmg_cli.c phgmg.h $(BUILD)/phgmg_impl_f.o
	@mkdir -p $(BUILD)
	$(CC) -std=c99 $(WARN) -O1 -march=native -Wdouble-promotion -DPHGMG_REAL_FLOAT -DPHGMG_IMPLEMENTATION_ELSEWHERE -o $@ $< $(BUILD)/phgmg_impl_f.o $(LDLIBS)

test-cli: $(BUILD)/phgmg $(BUILD)/phgmg-float
	sh tests/test_cli.sh $(BUILD)/phgmg $(BUILD)/phgmg-float
	sh tests/test_cli_defects4.sh $(BUILD)/phgmg $(BUILD)/phgmg-float
	sh tests/test_simulate.sh $(BUILD)/phgmg
	sh tests/test_stream.sh $(BUILD)/phgmg
	sh tests/test_lib_msgs4.sh $(BUILD)/phgmg
	sh tests/test_rom_dt.sh $(BUILD)/phgmg
	sh tests/test_rom_dt.sh $(BUILD)/phgmg-float
	sh tests/test_cli_workflow.sh $(BUILD)/phgmg
	/usr/bin/python3 tests/check_dae_bar.py $(BUILD)/phgmg 100 $(BUILD)/dae_bar
	sh tests/test_cli_lowrank.sh $(BUILD)/phgmg
	sh tests/test_dae_reduce.sh $(BUILD)/phgmg
	sh tests/test_cli_lowrank2.sh $(BUILD)/phgmg
	sh tests/test_lowrank_dae.sh $(BUILD)/phgmg

# The descriptor bar (N = 800, consistent mass, feedthrough, scrambled order)
# and its index-one variant through the command line against SciPy.
check-descriptor: $(BUILD)/phgmg
	/usr/bin/python3 tests/check_dae_bar.py $(BUILD)/phgmg 400 $(BUILD)/dae_bar400

# The examples share one compile of the implementation (the header's 26k
# lines are most of each example's compile time): each example still defines
# PHGMG_IMPLEMENTATION as a user's program would, and is compiled here with
# PHGMG_IMPLEMENTATION_ELSEWHERE and linked against this object. (Same flags,
# and ISO C's -ffp-contract=off: the numbers are those of a one-file build.)
$(BUILD)/phgmg_impl.o: phgmg.h
	@mkdir -p $(BUILD)
	@printf '#define PHGMG_IMPLEMENTATION\n#include "../phgmg.h"\n' > $(BUILD)/phgmg_impl.c
	$(CC) $(OPTFLAGS) -c -o $@ $(BUILD)/phgmg_impl.c

$(BUILD)/%: examples/%.c phgmg.h $(EXHDRS) $(BUILD)/phgmg_impl.o
	@mkdir -p $(BUILD)
	$(CC) $(OPTFLAGS) -DPHGMG_IMPLEMENTATION_ELSEWHERE -o $@ $< $(BUILD)/phgmg_impl.o $(LDLIBS)

# Reproduce Section 5 of the paper: tables on the terminal, CSVs and SVG figures in results/;
# then the non-polynomial Morse-chain example, the transport example and their checks.
demo: $(EXAMPLES)
	@mkdir -p results
	@start=$$(date +%s.%N); \
	./$(BUILD)/msd_linear --out results && ./$(BUILD)/msd_nonlinear --out results && \
	./$(BUILD)/msd_linear --lambda auto --rmin 8 --rmax 14 --rstep 6 --out results && \
	./$(BUILD)/msd_linear --generalization 8,12,16 --out results && \
	./$(BUILD)/morse_chain --out results && ./$(BUILD)/linear_bases --out results && \
	./$(BUILD)/fe_bar --n 200 --out results && ./$(BUILD)/transport_line --rmax 12 --out results && \
	./$(BUILD)/circuit_dae --out results && ./$(BUILD)/damped_chain --out results && \
	end=$$(date +%s.%N) && awk -v a=$$start -v b=$$end 'BEGIN { printf "make demo: total wall time %.2f s\n", b - a }' && \
	/usr/bin/python3 tests/check_claims.py results && /usr/bin/python3 tests/check_morse.py results && \
	/usr/bin/python3 tests/check_linear.py results && /usr/bin/python3 tests/check_fe_bar.py results && \
	/usr/bin/python3 tests/check_transport.py results && /usr/bin/python3 tests/check_circuit.py results && \
	/usr/bin/python3 tests/check_damped.py results

# Short fuzzing run of every reader of outside data (.npy in memory and
# streamed from a file and a pipe, binary model files) and of the CLI's
# argument handling: 60 s per target.
fuzz:
	sh tests/fuzz/run.sh 60

# Timings of every phase into bench/results.csv (not part of make test).
bench: phgmg.h examples
	sh bench/run.sh

clean:
	rm -rf $(BUILD) results tests/suites.inc bench/results.csv

# The low-rank benchmark (bench/bench_lowrank.c; bench/README.md), with OpenMP
# when the compiler has it (PHGMG_USE_OPENMP: phgmg_shifted_hinf's frequencies
# on all cores, the same values; OMP_NUM_THREADS=1 for one core):
#   ./build/bench_lowrank --model lattice --n 224 --r 20 --nw 200
$(BUILD)/bench_lowrank: bench/bench_lowrank.c bench/bench_args.h phgmg.h
	@mkdir -p $(BUILD)
	$(CC) $(OPTFLAGS) $$(if printf 'int main(void){return 0;}\n' | $(CC) -fopenmp -x c - -o /dev/null >/dev/null 2>&1; \
	  then echo -fopenmp -DPHGMG_USE_OPENMP; fi) -o $@ bench/bench_lowrank.c $(LDLIBS)

# The dense Lyapunov solver and its kernels against SciPy/OpenBLAS
# (bench/README.md, "Dense Lyapunov"; one thread, no OpenMP):
#   ./build/bench_lyap --n 1000 --dir /tmp/ly && /usr/bin/python3 bench/lyap_scipy.py /tmp/ly
$(BUILD)/bench_lyap: bench/bench_lyap.c phgmg.h examples/msd_models.h
	@mkdir -p $(BUILD)
	$(CC) $(OPTFLAGS) -o $@ bench/bench_lyap.c $(LDLIBS)

# The distributed phases' timings and communication, as JSON (bench/README.md,
# "The distributed offline phase: scaling model"; not part of make test):
#   mpirun -np P build/bench_mpi_phases --nloc 25000 > p1.json
#   /usr/bin/python3 bench/mpi_scaling.py p1.json ...
$(BUILD)/bench_mpi_phases: bench/bench_mpi_phases.c phgmg.h
	@mkdir -p $(BUILD)
	$(MPICC) -std=c99 $(WARN) -O2 -o $@ bench/bench_mpi_phases.c $(LDLIBS)

# Peak memory per rank of phgmg_mpi_reduce at a fixed global size (bench/README.md,
# "Memory per rank of the distributed offline phase"; not part of make test):
#   sh bench/mpi_memory/run.sh
$(BUILD)/bench_mpi_memory: bench/bench_mpi_memory.c tests/mpi/mem_chain.h phgmg.h
	@mkdir -p $(BUILD)
	$(MPICC) -std=c99 $(WARN) -O2 -o $@ bench/bench_mpi_memory.c $(LDLIBS)
