/* One translation unit for the test files that build the header in its
   default configuration (make test compiles the implementation once per
   unit instead of once per file: about 80 s less on two cores). Each file
   still defines PHGMG_STATIC and PHGMG_IMPLEMENTATION and builds on its own;
   the include guards make the repeats no-ops. Files that configure the
   implementation (PHGMG_MALLOC, thresholds: test_reduce, test_robust,
   test_rsvd, test_scale) stay units of their own. test_ph and test_sepfun are
   in tests/unity_b.c: their file-level names collide with files here.
   A test file missing from every unit fails the link (tests/suites.inc
   declares its suite). */
#define _POSIX_C_SOURCE 200809L /* test_defects, test_npy */
#include "test_api_structs.c"
#include "test_core.c"
#include "test_dae.c"
#include "test_defects.c"
#include "test_defects3.c"
#include "test_defects4.c"
#include "test_degen.c"
#include "test_deploy.c"
#include "test_descriptor.c"
#include "test_dissip.c"
#include "test_errors.c"
#include "test_general.c"
#include "test_hyper.c"
#include "test_linalg.c"
#include "test_linear.c"
#include "test_lowrank.c"
#include "test_npy.c"
#include "test_online.c"
#include "test_qm_wide.c"
#include "test_qm_ref.c"
#include "test_options.c"
#include "test_sparse.c"
#include "test_sparse_lu.c"
#include "test_sparse_perm.c"
#include "test_study.c"
#include "test_subnormal.c"
#include "test_dae_ports.c"
#include "test_setup.c"
#include "test_dae_sparse.c"
#include "test_sparse_class.c"
#include "test_balanced.c"
#include "test_workflow.c"
#include "test_pod_stream.c"
#include "test_dae_sparse_reduce.c"
#include "test_balanced2.c"
#include "test_springs.c"
#include "test_eksm.c"
