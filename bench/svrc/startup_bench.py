#!/usr/bin/env python3
"""Wall time of small meshing runs, best of 15: `svrc` (local commands only),
`svrc-remote` (every command linked, the CLI before session 16) and
`tetgen -pq2Q` (bench/RESULTS.md "Session 16: CLI start-up").

    python3 bench/svrc/startup_bench.py [BUILD_DIR] [FAMILY_DIR]

FAMILY_DIR: the run folders of `svrc_plc_bench --workdir DIR --keep families`
(optional); the point-set and small PLC families in it are added."""
import glob
import os
import shutil
import subprocess
import sys
import tempfile
import time

root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
build = os.path.abspath(sys.argv[1]) if len(sys.argv) > 1 else os.path.join(root, "build/release")
fam = sys.argv[2] if len(sys.argv) > 2 else None
corpus = os.environ.get("SVRC_CORPUS_DIR", os.path.join(root, "../shared/corpus"))
inputs = [os.path.join(corpus, f) for f in ("a_convex/cube.poly", "a_convex/tetra.poly",
                                            "b_internal/box_internal_facet.poly", "b_internal/box_in_box.poly",
                                            "e_spread/tiny_cube_in_box.poly",
                                            "e_spread/far_offset_close_points.poly")]
if fam:
    for d in sorted(glob.glob(os.path.join(fam, "*"))):
        name = os.path.basename(d).split("_", 1)[1]
        if name.startswith(("crease", "segment_facet", "fan", "skew_lines_200", "cube_maxvol", "nested")):
            continue
        inputs += glob.glob(d + "/*.poly") + glob.glob(d + "/*.node")
work = tempfile.mkdtemp()


def best_ms(cmd, n=15):
    best = 1e9
    for _ in range(n):
        t = time.perf_counter()
        subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, cwd=work)
        best = min(best, time.perf_counter() - t)
    return best * 1000


print("| input | svrc ms | svrc-remote ms | tetgen ms | svrc / tetgen |")
print("|---|---|---|---|---|")
for f in inputs:
    inp = os.path.join(work, "in" + os.path.splitext(f)[1])
    shutil.copy(f, inp)
    a = best_ms([os.path.join(build, "client/svrc"), "mesh", inp, "-o", os.path.join(work, "o.node"), "--quiet"])
    b = best_ms([os.path.join(build, "client/svrc-remote"), "mesh", inp, "-o", os.path.join(work, "o.node"),
                 "--quiet"])
    c = best_ms(["tetgen", "-pq2Q" if inp.endswith(".poly") else "-Q", inp])
    print(f"| {os.path.basename(f)} | {a:.2f} | {b:.2f} | {c:.2f} | {a / c:.2f} |")
shutil.rmtree(work)
