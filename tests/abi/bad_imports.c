/* A stand-in library for abi_imports_rejects_violations: it imports what libsinew.so
 * must not (stdio, a spin lock, a C11 mutex) next to what it may (malloc, free), so the
 * import checker has something to reject. Never installed or linked by anything. */
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>

int sw_bad_imports(const char *path, pthread_spinlock_t *lock);
int sw_bad_imports(const char *path, pthread_spinlock_t *lock) {
    void *p = malloc(16);
    free(p);
    pthread_spin_lock(lock);
    FILE *f = fopen(path, "r");
    int ok = f != NULL;
    if (f) fclose(f);
    pthread_spin_unlock(lock);
    return ok;
}
