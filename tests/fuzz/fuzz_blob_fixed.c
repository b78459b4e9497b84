/* fuzz_blob with the checksum fixed up before parsing (hostile blobs reach the semantic
 * checks) and every accepted blob stepped through the public API (fuzz_blob.c says how).
 * Seeded with a real baked blob, tests/fuzz/corpus/blob_fixed. */
#define SW_FUZZ_FIX_CHECKSUM
#define SW_FUZZ_STEP
#include "fuzz_blob.c"
