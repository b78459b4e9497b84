/* fuzz_blob with the checksum fixed up before parsing (hostile blobs reach the semantic
 * checks) and every accepted blob stepped through the public API (fuzz_blob.c says how).
 * Seeded (tests/fuzz/corpus/blob_fixed) with synth_4bones.blob, the 10 KB synthetic
 * character of tests/blob_synth.h (fixture_init seed 7) written by the real writer: in
 * 30 s it reached more coverage than the 46 KB baked cylinder (1,045 edges against 970)
 * at 3 times the executions a second, so the cylinder seeds fuzz_blob instead. The same
 * character with a render mesh (synth_render.blob, test_render_embed) and with the
 * condensation tet mesh as well (synth_cond.blob, test_blob_cond) and per-pair contact
 * sections too (synth_pairs.blob, test_blob_cond) seed the optional sections.
 * regress_pair_unreachable.blob is an input this harness found (CI, 2026-12-03) that
 * stepped forever: no pair-feature distance compared below infinity (finite but huge
 * values overflow), so no sample was nearest and the branch lookup walked twin_next from
 * index -1 (pair_space.c now counts such a pair as novel). */
#define SW_FUZZ_FIX_CHECKSUM
#define SW_FUZZ_STEP
#include "fuzz_blob.c"
