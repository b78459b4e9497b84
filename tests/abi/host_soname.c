/* A host as an engine builds it: linked against the shared libsinew, so the dynamic
 * loader looks the library up by its SONAME (libsinew.so.<major>), not by the
 * development symlink libsinew.so. Checks that this is what happened, and that the
 * loaded library accepts the headers the host was compiled with. */
#define _GNU_SOURCE /* dl_iterate_phdr, RTLD_NOLOAD */
#include <dlfcn.h>
#include <link.h>
#include <stdio.h>
#include <string.h>

#include <sinew/sinew.h>

#define SW_STR2(x) #x
#define SW_STR(x) SW_STR2(x)
#define SW_SONAME "libsinew.so." SW_STR(SINEW_VERSION_MAJOR)

typedef struct {
    int count;      /* loaded objects whose file name starts with "libsinew" */
    char path[512]; /* the last of them */
} sw_found;

static int sw_find_sinew(struct dl_phdr_info *info, size_t size, void *data) {
    sw_found *found = data;
    const char *name = info->dlpi_name ? info->dlpi_name : "";
    const char *base = strrchr(name, '/');
    (void)size;
    base = base ? base + 1 : name;
    if (strncmp(base, "libsinew", 8) == 0) {
        found->count++;
        snprintf(found->path, sizeof found->path, "%s", name);
    }
    return 0;
}

int main(void) {
    sw_found found = {0, ""};
    const char *base;
    void *handle, *sym;
    int (*compatible)(uint32_t) = NULL;
    int failures = 0;

    if (!sinew_version_compatible(SINEW_VERSION)) {
        fprintf(stderr, "host: headers 0x%06lx are not compatible with library %s\n",
                (unsigned long)SINEW_VERSION, sinew_version_string());
        failures++;
    }
    if (sinew_version_compatible(SINEW_VERSION + (1u << 16))) {
        fprintf(stderr, "host: library accepts a future major version\n");
        failures++;
    }

    /* The loader names the object after the DT_NEEDED entry it resolved, which is the
     * SONAME recorded at link time. */
    dl_iterate_phdr(sw_find_sinew, &found);
    base = strrchr(found.path, '/');
    base = base ? base + 1 : found.path;
    if (found.count != 1 || strcmp(base, SW_SONAME) != 0) {
        fprintf(stderr, "host: expected exactly one %s loaded, found %d (last: '%s')\n", SW_SONAME,
                found.count, found.path);
        failures++;
    }

    /* Already loaded under its SONAME: dlopen must find it without loading a copy, and
     * the symbol it exports must be the very function the host linked to. */
    handle = dlopen(SW_SONAME, RTLD_NOW | RTLD_NOLOAD);
    if (!handle) {
        fprintf(stderr, "host: dlopen(%s, RTLD_NOLOAD) failed: %s\n", SW_SONAME, dlerror());
        failures++;
    } else {
        sym = dlsym(handle, "sinew_version_compatible");
        if (sym) memcpy(&compatible, &sym, sizeof compatible); /* POSIX-sanctioned cast */
        if (!compatible || compatible != sinew_version_compatible || !compatible(SINEW_VERSION)) {
            fprintf(stderr, "host: dlsym(sinew_version_compatible) is not the linked function\n");
            failures++;
        }
        dlclose(handle);
    }

    printf("host: %s from %s, version %s: %s\n", SW_SONAME, found.path, sinew_version_string(),
           failures ? "FAILED" : "ok");
    return failures ? 1 : 0;
}
