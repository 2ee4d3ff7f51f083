#!/usr/bin/env python3
"""Peak heap of a run by data structure, from a valgrind massif file (issue #5;
bench/RESULTS.md "Session 51").

    SVRC_HUGE_PAGES=0 SVRC_MMAP_THRESHOLD=0 valgrind --tool=massif --threshold=0.5 \\
        --time-unit=B --massif-out-file=m.out build/release/client/svrc mesh cube.poly \\
        --max-volume 1e-4 -o out.node --quiet --deadline 3000s
    bench/svrc/massif_categories.py m.out 18377      # the output's tets, for B/tet

The peak snapshot's allocation tree is walked from the top; a node is
charged to the first category its function matches (generic growth helpers —
ReserveForAppend, GrowExactly, PodVector, std:: internals — are looked through
to their callers). What massif left below its threshold is reported as such.
"""
import re
import sys


def parse(path):
    """(heap bytes, [(depth, bytes, name)]) of the peak snapshot."""
    lines = open(path).read().split('\n')
    snaps, cur = [], None
    for i, line in enumerate(lines):
        if line.startswith('snapshot='):
            cur = {'i': i}
            snaps.append(cur)
        elif cur is not None and line.startswith('mem_heap_B='):
            cur['heap'] = int(line.split('=')[1])
        elif cur is not None and line.startswith('heap_tree='):
            cur['tree'] = line.split('=')[1]
    peak = [s for s in snaps if s.get('tree') == 'peak']
    snap = peak[0] if peak else max(snaps, key=lambda s: s.get('heap', 0))
    j = snap['i']
    while not lines[j].startswith('heap_tree='):
        j += 1
    nodes = []
    for line in lines[j + 1:]:
        if line.startswith('#'):
            break
        m = re.match(r'^( *)n(\d+): (\d+) (.*)$', line)
        if m:
            nodes.append((len(m.group(1)), int(m.group(3)), m.group(4)))
    return snap['heap'], nodes


CATEGORIES = [
    ('M_Ω tets', r'Delaunay3::GrowTets'),
    ('M_Ω per vertex', r'Delaunay3::ReserveVertex|Delaunay3::AddVertex'),
    ('M_Ω neighbour lists', r'StoreAdj|AdjEntry|NeighborsView|StarAndNeighbors'),
    ('M_Ω circumcentre cache', r'CachedCircumcenter'),
    ('M_Ω size memo', r'MemoSlot'),
    ('location graph', r'LocationGraph'),
    ('balls', r'BallStore'),
    ('facet/segment meshes', r'Delaunay2|Delaunay1|FacetMesh|SegmentMesh|FacetRegion'),
    ('points', r'PointStore'),
    ('queues/events', r'WorkQueues|EventHandle|EnqueueTetIfBad|RefreshEvents|RefreshFacetEvents'),
    ('cell certificates', r'CellCert'),
    ('size targets', r'PropagateSizeTargets|SetSizeTargets'),
    ('edge table', r'EdgeTableFor'),
    ('output/labelling/sliver', r'BuildOutputMesh|Label|Sliver|Assemble|Output|TetLabel'),
]


def category(name):
    # A growth helper's template argument can name the category
    # (PodVector<Refiner::CellCert>); else it is looked through.
    for cat, rx in CATEGORIES:
        if re.search(rx, name):
            return cat
    return None


def main():
    heap, nodes = parse(sys.argv[1])
    tets = float(sys.argv[2]) if len(sys.argv) > 2 else 0
    out = {}

    def charge(cat, b):
        out[cat] = out.get(cat, 0) + b

    def walk(idx, depth):
        d, b, name = nodes[idx]
        kids, k = [], idx + 1
        while k < len(nodes) and nodes[k][0] > d:
            if nodes[k][0] == d + 1:
                kids.append(k)
            k += 1
        cat = category(name) if depth > 0 else None
        if cat is not None:
            charge(cat, b)
        elif not kids:
            if depth > 0:
                label = 'below threshold' if 'threshold' in name else re.sub(r'\(.*', '', name.split(':', 1)[-1]).strip()
                charge('other (' + label[:50] + ')', b)
        else:
            for x in kids:
                walk(x, depth + 1)
            rest = b - sum(nodes[x][1] for x in kids)
            if rest > 0 and depth > 0:
                charge('other (below threshold)', rest)

    walk(0, 0)
    print(f'peak heap {heap:,d} B' + (f', {heap / tets:.1f} B/tet' if tets else ''))
    for cat, b in sorted(out.items(), key=lambda x: -x[1]):
        print(f'  {cat:32s} {b:13,d} {100 * b / heap:5.1f}%' + (f' {b / tets:7.1f} B/tet' if tets else ''))


if __name__ == '__main__':
    main()
