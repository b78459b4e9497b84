/* Bakes the step contract's character (the finger of test_step_contract.c, the same
 * bake_fixture_make call) and writes its blob and clip into the folder given, for the
 * contract's run against libsinew.so (contract_fixture.h). A CTest fixture setup.
 *
 * usage: contract_fixture_write DIR */
#include <sys/stat.h>

#include "bake_fixture.h"
#include "contract_fixture.h"

int main(int argc, char **argv) {
    if (argc != 2) {
        fprintf(stderr, "usage: %s DIR\n", argv[0]);
        return 2;
    }
    if (mkdir(argv[1], 0777) != 0) {
        struct stat s;
        if (stat(argv[1], &s) != 0 || !S_ISDIR(s.st_mode)) {
            fprintf(stderr, "contract_fixture_write: cannot make %s\n", argv[1]);
            return 1;
        }
    }
    bake_fixture f;
    if (!bake_fixture_make(&f, "finger", 2000, 12, 1)) {
        fprintf(stderr, "contract_fixture_write: the bake failed\n");
        return 1;
    }
    uint32_t nb = (uint32_t)f.ch.skel.nbones;
    int frames = f.ch.clip.nframes;
    float *poses = malloc(sizeof(float) * 12 * nb * (size_t)frames);
    int ok = poses != NULL;
    for (int k = 0; ok && k < frames; ++k)
        bake_fixture_pose(&f, k, poses + (size_t)12 * nb * k);
    ok = ok && contract_fixture_save(argv[1], f.data, f.size, poses, nb, frames);
    free(poses);
    bake_fixture_free(&f);
    if (!ok) {
        fprintf(stderr, "contract_fixture_write: cannot write into %s\n", argv[1]);
        return 1;
    }
    printf("contract_fixture_write: %u bones, %d frames into %s\n", nb, frames, argv[1]);
    return 0;
}
