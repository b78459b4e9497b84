#!/usr/bin/env python3
"""Compiles the C examples of the README and docs/integration.md against the public headers,
so that a renamed function or a changed signature cannot leave a page that no longer builds.

Each page's ```c blocks, in order, become the body of one function (a later block uses what
an earlier one declared, as a reader does); #include lines and static helper functions are
hoisted to file scope, and `{ ... }` elisions become empty bodies. The host's own names that
the pages use without declaring (the actor's matrix, the bone array, dt, ...) are declared
in HOST below with the types the API takes. A #define block (the version macros) is checked
against the installed header's values instead.

usage: docs_snippets.py SOURCE_DIR CC
"""
import os
import re
import subprocess
import sys
import tempfile

PAGES = ["README.md", "docs/integration.md", "docs/versioning.md"]

HOST = """
#include <stdint.h>
#include <sinew/sinew.h>
#include <sinew/sinew_world.h>
extern double actor[12];
extern float *bones, *positions, *normals, *pos, *nrm, *xa, *xb, dt, y;
extern uint32_t nbones, nverts, nv, nt;
extern const float *level_xyz;
extern const uint32_t *level_tris;
extern sinew_instance *inst, *a, *b;
extern sinew_blob *blob;
extern sinew_world *world;
extern sinew_instance_def def;
extern sinew_collider_id surf_a, surf_b;
extern void *my_renderer;
"""


def blocks(text):
    return re.findall(r"^```c\n(.*?)^```", text, flags=re.S | re.M)


def version_macros(root, block):
    """A #define block: each macro's value as the header defines it."""
    header = open(os.path.join(root, "plugin_api/include/sinew/sinew_base.h")).read()
    bad = []
    for name, value in re.findall(r"^#define (SINEW_VERSION_\w+) (\S+)", block, flags=re.M):
        m = re.search(r"^#define %s\s+(\S+)" % name, header, flags=re.M)
        if not m or m.group(1) != value:
            bad.append("%s is %s on the page, %s in sinew_base.h" %
                       (name, value, m.group(1) if m else "missing"))
    return bad


def translation_unit(page_blocks):
    top, body = [], []
    for blk in page_blocks:
        for line in blk.splitlines():
            if line.startswith("#include") or line.startswith("static "):
                top.append(line.replace("{ ... }", "{}"))
            else:
                body.append(line)
    return (HOST + "\n".join(top) + "\nvoid page_example(void);\nvoid page_example(void) {\n" +
            "\n".join(body) + "\n}\n")


def main():
    root, cc = sys.argv[1], sys.argv[2]
    failed = 0
    for page in PAGES:
        code = [b for b in blocks(open(os.path.join(root, page)).read())]
        defines = [b for b in code if b.lstrip().startswith("#define")]
        code = [b for b in code if b not in defines]
        for b in defines:
            for msg in version_macros(root, b):
                print("%s: %s" % (page, msg))
                failed += 1
        if not code:
            continue
        with tempfile.NamedTemporaryFile("w", suffix=".c", delete=False) as f:
            f.write(translation_unit(code))
        r = subprocess.run([cc, "-std=c17", "-fsyntax-only", "-Wall", "-Wextra", "-Werror",
                            "-Wno-unused-variable", "-Wno-unused-parameter",
                            "-Wno-unused-function", "-Wno-unused-but-set-variable",
                            "-I" + os.path.join(root, "plugin_api/include"), f.name],
                           capture_output=True, text=True)
        os.unlink(f.name)
        if r.returncode != 0:
            print("%s: its C examples do not compile against the public headers:\n%s" %
                  (page, r.stderr))
            failed += 1
        else:
            print("%s: %d C example(s) compile" % (page, len(code)))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
