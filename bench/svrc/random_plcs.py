#!/usr/bin/env python3
"""Random PLCs for svrc's robustness sweep (bench/svrc/random_sweep.sh).

random_plcs.py KIND SEED OUT.poly writes one TetGen .poly file, the same
bytes for the same KIND and SEED (Python's random.Random; floats written
with repr, so they round-trip). Kinds (all inside or on the unit box):
  pts       isolated points, some in close pairs or near a wall (1e-2..1e-6)
  segs      free segments and isolated points
  float     1-3 triangles/squares floating inside (acute corners: crease points)
  cut       the box cut by a random plane (creases where it meets the walls)
  tet       a random tetrahedron, 40% of them flattened (sharp dihedrals)
  mixed     a cut plus free segments and points
  hull      the convex hull of 5-12 random points, 30% of them squashed
  segfacet  segments standing on the floor at 2-89 degrees
  near      features 1e-2..1e-7 from a wall or from each other
  prism     a star-shaped (non-convex) polygon extruded, its own region
            (attribute, sometimes a max volume), sometimes tilted or a hole
  holed     floating star-shaped facets with a polygonal hole, and a
            region bound on the box
  fan       2-6 floating rectangles around one shared edge, angles between
            them from 0.5 to 60 degrees
  stack     a block standing on the floor (its footprint a polygon of the
            floor facet), sometimes a rotated block on top of it, regions
KIND+rot (e.g. prism+rot) is KIND's PLC turned by a random rotation about
the box's centre (session 38): every facet is then slanted, its points
coplanar only up to rounding.
KIND+far (also KIND+rot+far) moves it far from the origin: scaled by 1e-2
about the box's centre and translated by (12345.678, -9876.54, 4321.0), so
its coordinates carry ~1e-12 of rounding on a model of size 1e-2.
KIND+bend (before +rot and +far) moves every node by a random vector of
length up to 2e-9 of the smallest facet containing it (session 39): facets
planar only to ~4e-9 of their diameter, which validation accepts (TetGen's
-T 1e-8), and points near but no longer exactly on other facets' edges.
Some outputs are invalid PLCs (intersecting features); the sweep validates
first and skips them.
"""
import random, sys, math, os

BOX = [(0,0,0),(1,0,0),(1,1,0),(0,1,0),(0,0,1),(1,0,1),(1,1,1),(0,1,1)]
FACES = [[0,3,2,1],[4,5,6,7],[0,1,5,4],[1,2,6,5],[2,3,7,6],[3,0,4,7]]
EDGES = [(0,1),(1,2),(2,3),(3,0),(4,5),(5,6),(6,7),(7,4),(0,4),(1,5),(2,6),(3,7)]

def write_poly(path, nodes, facets, holes=(), regions=()):
    with open(path, 'w') as f:
        f.write(f"{len(nodes)} 3 0 0\n")
        for i, p in enumerate(nodes):
            f.write(f"{i+1} {p[0]!r} {p[1]!r} {p[2]!r}\n")
        f.write(f"{len(facets)} 1\n")
        for facet in facets:
            polys, marker = facet[0], facet[1]
            fholes = facet[2] if len(facet) > 2 else []
            f.write(f"{len(polys)} {len(fholes)} {marker}\n")
            for poly in polys:
                f.write(f"{len(poly)} " + " ".join(str(v+1) for v in poly) + "\n")
            for i, h in enumerate(fholes):
                f.write(f"{i+1} {h[0]!r} {h[1]!r} {h[2]!r}\n")
        f.write(f"{len(holes)}\n")
        for i, h in enumerate(holes):
            f.write(f"{i+1} {h[0]!r} {h[1]!r} {h[2]!r}\n")
        f.write(f"{len(regions)}\n")
        for i, r in enumerate(regions):
            f.write(f"{i+1} {r[0]!r} {r[1]!r} {r[2]!r} {r[3]} {r[4]!r}\n")

def rnd_interior(rng, lo=0.05, hi=0.95):
    return tuple(rng.uniform(lo, hi) for _ in range(3))

def box_facets(extra=None):
    extra = extra or {}
    return [([f] + extra.get(i, []), 1) for i, f in enumerate(FACES)]

def gen_pts(rng):
    nodes = list(BOX)
    n = rng.randint(1, 30)
    for _ in range(n):
        p = rnd_interior(rng)
        nodes.append(p)
        r = rng.random()
        if r < 0.2:  # a close pair
            e = 10 ** -rng.uniform(2, 6)
            d = [rng.gauss(0, 1) for _ in range(3)]
            l = math.sqrt(sum(x*x for x in d))
            nodes.append(tuple(p[k] + e * d[k] / l for k in range(3)))
        elif r < 0.35:  # a point near a face
            e = 10 ** -rng.uniform(2, 6)
            k = rng.randrange(3)
            q = list(p); q[k] = e if rng.random() < 0.5 else 1 - e
            nodes.append(tuple(q))
    return nodes, box_facets()

def add_free_segments_and_points(rng, nodes, facets, segments, points):
    """rng.randint(*segments) free segments (marker 2), then rng.randint(*points) isolated points."""
    for _ in range(rng.randint(*segments)):
        a = rnd_interior(rng); b = rnd_interior(rng)
        nodes += [a, b]
        facets.append(([[len(nodes)-2, len(nodes)-1]], 2))
    for _ in range(rng.randint(*points)):
        nodes.append(rnd_interior(rng))

def gen_segs(rng):
    nodes = list(BOX)
    facets = box_facets()
    add_free_segments_and_points(rng, nodes, facets, (1, 5), (0, 5))
    return nodes, facets

def plane_basis(n):
    a = (1.0, 0.0, 0.0) if abs(n[0]) < 0.9 else (0.0, 1.0, 0.0)
    u = cross(n, a); lu = norm(u); u = tuple(x/lu for x in u)
    v = cross(n, u)
    return u, v

def cross(a, b):
    return (a[1]*b[2]-a[2]*b[1], a[2]*b[0]-a[0]*b[2], a[0]*b[1]-a[1]*b[0])

def norm(a):
    return math.sqrt(sum(x*x for x in a))

def random_unit(rng):
    n = [rng.gauss(0, 1) for _ in range(3)]; l = norm(n)
    return tuple(x / l for x in n)

def gen_float(rng):
    nodes = list(BOX)
    facets = box_facets()
    k = rng.randint(1, 3)
    for _ in range(k):
        c = rnd_interior(rng, 0.3, 0.7)
        n = random_unit(rng)
        # sometimes nearly axis aligned
        if rng.random() < 0.3:
            n = list(n); j = rng.randrange(3)
            n = [x * 1e-3 if i != j else 1.0 for i, x in enumerate(n)]
            l = norm(n); n = tuple(x/l for x in n)
        u, v = plane_basis(n)
        m = rng.choice([3, 3, 4])
        r = rng.uniform(0.05, 0.25)
        if m == 3:
            angs = sorted(rng.uniform(0, 2*math.pi) for _ in range(3))
        else:
            angs = [0, math.pi/2, math.pi, 3*math.pi/2]
        base = len(nodes)
        for a in angs:
            nodes.append(tuple(c[i] + r*(math.cos(a)*u[i] + math.sin(a)*v[i]) for i in range(3)))
        facets.append(([list(range(base, base+len(angs)))], 3))
    return nodes, facets

def gen_cut(rng):
    nodes = list(BOX)
    c = rnd_interior(rng, 0.35, 0.65)
    n = random_unit(rng)
    d = sum(n[i]*c[i] for i in range(3))
    s = [sum(n[i]*p[i] for i in range(3)) - d for p in BOX]
    if min(abs(x) for x in s) < 1e-3:
        return None
    edge_pt = {}
    for (a, b) in EDGES:
        if (s[a] < 0) != (s[b] < 0):
            t = s[a] / (s[a] - s[b])
            p = tuple(BOX[a][i] + t*(BOX[b][i]-BOX[a][i]) for i in range(3))
            edge_pt[(a, b)] = len(nodes); edge_pt[(b, a)] = len(nodes)
            nodes.append(p)
    facets = []
    for fi, f in enumerate(FACES):
        ring = []
        on = []
        for j in range(4):
            a, b = f[j], f[(j+1) % 4]
            ring.append(a)
            if (a, b) in edge_pt:
                ring.append(edge_pt[(a, b)]); on.append(edge_pt[(a, b)])
        polys = [ring]
        if len(on) == 2:
            polys.append(on)
        facets.append((polys, 1))
    cut = sorted(set(edge_pt.values()))
    cen = tuple(sum(nodes[i][k] for i in cut)/len(cut) for k in range(3))
    u, v = plane_basis(n)
    cut.sort(key=lambda i: math.atan2(sum((nodes[i][k]-cen[k])*v[k] for k in range(3)), sum((nodes[i][k]-cen[k])*u[k] for k in range(3))))
    facets.append(([cut], 5))
    return nodes, facets

def gen_tet(rng):
    while True:
        p = [rnd_interior(rng, 0, 1) for _ in range(4)]
        if rng.random() < 0.4:  # flatten: pull the 4th point toward the plane of the others
            a, b, c = p[0], p[1], p[2]
            nn = cross(tuple(b[i]-a[i] for i in range(3)), tuple(c[i]-a[i] for i in range(3)))
            l = norm(nn)
            if l < 1e-6: continue
            nn = tuple(x/l for x in nn)
            h = sum((p[3][i]-a[i])*nn[i] for i in range(3))
            f = 10 ** -rng.uniform(0.5, 2.5)
            p[3] = tuple(p[3][i] - (1-f)*h*nn[i] for i in range(3))
        vol = sum(cross(tuple(p[1][i]-p[0][i] for i in range(3)), tuple(p[2][i]-p[0][i] for i in range(3)))[k]*(p[3][k]-p[0][k]) for k in range(3))
        if abs(vol) > 1e-6:
            break
    if vol < 0:
        p[1], p[2] = p[2], p[1]
    # faces outward: (0,2,1),(0,1,3),(1,2,3),(0,3,2)
    facets = [([[0,2,1]],1),([[0,1,3]],1),([[1,2,3]],1),([[0,3,2]],1)]
    return p, facets

def gen_mixed(rng):
    r = gen_cut(rng)
    if r is None:
        return None
    nodes, facets = r
    add_free_segments_and_points(rng, nodes, facets, (0, 2), (0, 4))
    return nodes, facets

GENS = dict(pts=gen_pts, segs=gen_segs, float=gen_float, cut=gen_cut, tet=gen_tet, mixed=gen_mixed)


def sub(a, b): return (a[0]-b[0], a[1]-b[1], a[2]-b[2])
def dot(a, b): return a[0]*b[0]+a[1]*b[1]+a[2]*b[2]

def hull(pts):
    """Incremental convex hull (small n); returns outward triangles or None if degenerate."""
    n = len(pts)
    def vol(a, b, c, d):
        return dot(cross(sub(pts[b], pts[a]), sub(pts[c], pts[a])), sub(pts[d], pts[a]))
    if abs(vol(0, 1, 2, 3)) < 1e-9:
        return None
    faces = [(0, 1, 2), (0, 2, 3), (0, 3, 1), (1, 3, 2)]
    if vol(0, 1, 2, 3) > 0:
        faces = [(a, c, b) for (a, b, c) in faces]
    for i in range(4, n):
        vis = [f for f in faces if vol(f[0], f[1], f[2], i) > 1e-12]
        if not vis:
            continue
        edges = {}
        for f in vis:
            for e in ((f[0], f[1]), (f[1], f[2]), (f[2], f[0])):
                edges[e] = edges.get(e, 0) + 1
        horizon = [e for e in edges if (e[1], e[0]) not in edges]
        faces = [f for f in faces if f not in vis] + [(e[0], e[1], i) for e in horizon]
    used = sorted({v for f in faces for v in f})
    remap = {v: k for k, v in enumerate(used)}
    return [pts[v] for v in used], [tuple(remap[v] for v in f) for f in faces]

def gen_hull(rng):
    m = rng.randint(5, 12)
    pts = [tuple(rng.uniform(0, 1) for _ in range(3)) for _ in range(m)]
    if rng.random() < 0.3:  # squash one axis: thin slabs, sharp edges
        k = rng.randrange(3); s = 10 ** -rng.uniform(0.5, 1.5)
        pts = [tuple(p[i] * (s if i == k else 1) for i in range(3)) for p in pts]
    r = hull(pts)
    if r is None:
        return None
    nodes, tris = r
    return nodes, [([list(t)], 1) for t in tris]

GENS['hull'] = gen_hull

def gen_segfacet(rng):
    """Segments standing on the floor (z=0) at random angles, some grazing."""
    nodes = list(BOX)
    facets = box_facets()
    floor_extra = []
    for _ in range(rng.randint(1, 3)):
        a = (rng.uniform(0.1, 0.9), rng.uniform(0.1, 0.9), 0.0)
        ang = rng.choice([rng.uniform(2, 89), rng.uniform(20, 89)]) * math.pi / 180
        az = rng.uniform(0, 2 * math.pi)
        L = rng.uniform(0.1, 0.5)
        b = (a[0] + L * math.cos(ang) * math.cos(az), a[1] + L * math.cos(ang) * math.sin(az), L * math.sin(ang))
        if not all(0.02 < b[i] < 0.98 for i in range(3)):
            continue
        a2 = (min(max(a[0] + rng.uniform(-0.08, 0.08), 0.02), 0.98), min(max(a[1] + rng.uniform(-0.08, 0.08), 0.02), 0.98), 0.0)
        nodes += [a, b, a2]
        floor_extra.append([len(nodes) - 3, len(nodes) - 1])
        facets.append(([[len(nodes) - 3, len(nodes) - 2]], 2))
    if not floor_extra:
        return None
    facets[0] = (facets[0][0] + floor_extra, 1)
    return nodes, facets

GENS['segfacet'] = gen_segfacet


def gen_near(rng):
    """Features very close to the walls or to each other (large spread)."""
    nodes = list(BOX)
    facets = box_facets()
    kind = rng.randrange(3)
    gap = 10 ** -rng.uniform(2, 7)
    if kind == 0:  # a triangle nearly parallel to the floor, gap above it, tilted by up to 1 degree
        tilt = math.radians(rng.uniform(0, 1))
        c = (rng.uniform(0.3, 0.7), rng.uniform(0.3, 0.7))
        r = rng.uniform(0.1, 0.25)
        base = len(nodes)
        for a in sorted(rng.uniform(0, 2 * math.pi) for _ in range(3)):
            x, y = c[0] + r * math.cos(a), c[1] + r * math.sin(a)
            nodes.append((x, y, gap + r * (1 + math.cos(a)) * math.tan(tilt)))
        facets.append(([list(range(base, base + 3))], 3))
    elif kind == 1:  # a free segment ending gap away from a wall
        a = rnd_interior(rng, 0.2, 0.8)
        b = (a[0] + rng.uniform(-0.2, 0.2), a[1] + rng.uniform(-0.2, 0.2), gap)
        nodes += [a, b]
        facets.append(([[len(nodes) - 2, len(nodes) - 1]], 2))
    else:  # two floating triangles nearly touching
        c = rnd_interior(rng, 0.35, 0.65)
        base = len(nodes)
        for k in range(2):
            z = c[2] + (gap if k else 0)
            rr = rng.uniform(0.1, 0.2)
            for a in sorted(rng.uniform(0, 2 * math.pi) for _ in range(3)):
                nodes.append((c[0] + rr * math.cos(a), c[1] + rr * math.sin(a), z + rng.uniform(-1, 1) * gap * 0.4))
            facets.append(([list(range(base + 3 * k, base + 3 * k + 3))], 3))
    return nodes, facets

GENS['near'] = gen_near

def star_polygon(rng, c, n, rmin, rmax):
    """n points around c (2D) at sorted random angles: a simple, star-shaped polygon."""
    angs = sorted(rng.uniform(0, 2 * math.pi) for _ in range(n))
    gaps = [b - a for a, b in zip(angs, angs[1:] + [angs[0] + 2 * math.pi])]
    if min(gaps) < 1e-3 or max(gaps) > 0.9 * math.pi:  # a gap past pi: the edge passes c on the other side
        return None
    return [(c[0] + r * math.cos(a), c[1] + r * math.sin(a)) for a, r in ((a, rng.uniform(rmin, rmax)) for a in angs)]

def gen_prism(rng):
    """A star-shaped polygon extruded along z (reflex vertical edges: sharp
    dihedral angles outside the prism), its inside a region of its own."""
    n = rng.randint(4, 14)
    c = (rng.uniform(0.4, 0.6), rng.uniform(0.4, 0.6))
    poly = star_polygon(rng, c, n, 0.04, 0.35)
    if poly is None:
        return None
    z0, z1 = rng.uniform(0.05, 0.45), rng.uniform(0.55, 0.95)
    tilt = rng.random() < 0.3
    a = math.radians(rng.uniform(-20, 20)) if tilt else 0.0
    def place(x, y, z):  # a tilt about the x axis through the box centre
        y2 = 0.5 + (y - 0.5) * math.cos(a) - (z - 0.5) * math.sin(a)
        z2 = 0.5 + (y - 0.5) * math.sin(a) + (z - 0.5) * math.cos(a)
        return (x, y2, z2)
    nodes = list(BOX)
    b = len(nodes)
    nodes += [place(x, y, z0) for x, y in poly]
    nodes += [place(x, y, z1) for x, y in poly]
    if not all(0.01 < q[i] < 0.99 for q in nodes[b:] for i in range(3)):
        return None
    facets = box_facets()
    facets.append(([list(reversed(range(b, b + n)))], 2))
    facets.append(([list(range(b + n, b + 2 * n))], 2))
    for i in range(n):
        j = (i + 1) % n
        facets.append(([[b + i, b + j, b + n + j, b + n + i]], 4))
    mid = place(c[0], c[1], (z0 + z1) / 2)
    regions = [(0.005, 0.005, 0.005, 1, 0.0), (mid[0], mid[1], mid[2], 2, rng.choice([0.0, 1e-3, 3e-4]))]
    holes = []
    if rng.random() < 0.2:  # the prism is a hole instead
        regions = regions[:1]
        holes = [mid]
    return nodes, facets, holes, regions

def gen_holed(rng):
    """1-2 floating star-shaped facets, each with a star-shaped hole around its
    centre (a facet hole point), at random orientations; the box is a region
    with a max volume."""
    nodes = list(BOX)
    facets = box_facets()
    k = rng.randint(1, 2)
    for _ in range(k):
        c3 = rnd_interior(rng, 0.35, 0.65)
        nrm = random_unit(rng)
        if rng.random() < 0.4:
            nrm = (0.0, 0.0, 1.0)
        u, v = plane_basis(nrm)
        outer = star_polygon(rng, (0, 0), rng.randint(3, 9), 0.12, 0.3)
        inner = star_polygon(rng, (0, 0), rng.randint(3, 7), 0.02, 0.1)
        if outer is None or inner is None:
            return None
        def lift(p):
            return tuple(c3[i] + p[0] * u[i] + p[1] * v[i] for i in range(3))
        bo = len(nodes); nodes += [lift(p) for p in outer]
        bi = len(nodes); nodes += [lift(p) for p in inner]
        facets.append(([list(range(bo, bo + len(outer))), list(range(bi, bi + len(inner)))], 3, [c3]))
    regions = [(0.5, 0.5, 0.01, 7, rng.choice([1e-3, 1e-2]))]
    return nodes, facets, (), regions

def gen_fan(rng):
    nodes = list(BOX)
    facets = box_facets()
    c = rnd_interior(rng, 0.4, 0.6)
    ax = random_unit(rng)
    if rng.random() < 0.4:
        ax = (0.0, 0.0, 1.0)
    u, v = plane_basis(ax)
    h = rng.uniform(0.1, 0.3)
    a0 = tuple(c[i] - h * ax[i] for i in range(3))
    a1 = tuple(c[i] + h * ax[i] for i in range(3))
    nodes += [a0, a1]
    k = rng.randint(2, 6)
    ang = rng.uniform(0, 2 * math.pi)
    for j in range(k):
        if j:
            ang += math.radians(rng.choice([rng.uniform(0.5, 5), rng.uniform(5, 60)]))
        w = rng.uniform(0.1, 0.3)
        d = tuple(math.cos(ang) * u[i] + math.sin(ang) * v[i] for i in range(3))
        b0 = tuple(a0[i] + w * d[i] for i in range(3))
        b1 = tuple(a1[i] + w * d[i] for i in range(3))
        nodes += [b1, b0]
        facets.append(([[8, 9, len(nodes) - 2, len(nodes) - 1]], 3 + j))
    if not all(0.01 < q[i] < 0.99 for q in nodes[8:] for i in range(3)):
        return None
    return nodes, facets

def gen_stack(rng):
    nodes = list(BOX)
    x0, y0 = rng.uniform(0.1, 0.4), rng.uniform(0.1, 0.4)
    x1, y1 = x0 + rng.uniform(0.2, 0.5), y0 + rng.uniform(0.2, 0.5)
    z1 = rng.uniform(0.1, 0.6)
    b = len(nodes)
    nodes += [(x0, y0, 0.0), (x1, y0, 0.0), (x1, y1, 0.0), (x0, y1, 0.0), (x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)]
    foot = [b, b + 1, b + 2, b + 3]
    facets = box_facets({0: [foot]})
    top = [b + 4, b + 5, b + 6, b + 7]
    top_polys = [top]
    regions = [(0.99, 0.99, 0.99, 1, 0.0), ((x0 + x1) / 2, (y0 + y1) / 2, z1 / 2, 2, rng.choice([0.0, 1e-3, 1e-4]))]
    if rng.random() < 0.6:  # a block on top, rotated about z, inside the top face
        cx, cy = (x0 + x1) / 2, (y0 + y1) / 2
        r = min(x1 - x0, y1 - y0) / 2 * rng.uniform(0.3, 0.95)
        t = rng.uniform(0, math.pi / 2)
        z2 = z1 + rng.uniform(0.05, 0.3)
        ring = [(cx + r * math.cos(t + q * math.pi / 2), cy + r * math.sin(t + q * math.pi / 2)) for q in range(4)]
        c0 = len(nodes)
        nodes += [(x, y, z1) for x, y in ring] + [(x, y, z2) for x, y in ring]
        top_polys.append([c0, c0 + 1, c0 + 2, c0 + 3])
        facets.append(([[c0 + 4, c0 + 5, c0 + 6, c0 + 7]], 6))
        for q in range(4):
            facets.append(([[c0 + q, c0 + (q + 1) % 4, c0 + 4 + (q + 1) % 4, c0 + 4 + q]], 6))
        regions.append((cx, cy, (z1 + z2) / 2, 3, rng.choice([0.0, 1e-3])))
    facets.append((top_polys, 5))
    for q in range(4):
        facets.append(([[foot[q], foot[(q + 1) % 4], top[(q + 1) % 4], top[q]]], 5))
    return nodes, facets, (), regions

GENS['prism'] = gen_prism
GENS['holed'] = gen_holed
GENS['fan'] = gen_fan
GENS['stack'] = gen_stack

def random_rotation(rng):
    """A uniformly random rotation matrix (a unit quaternion of four normal deviates)."""
    q = [rng.gauss(0, 1) for _ in range(4)]
    n = math.sqrt(sum(x * x for x in q))
    w, x, y, z = (c / n for c in q)
    return [[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]]

def map_plc(point, volume_factor, nodes, facets, holes=(), regions=()):
    """The PLC with every point (nodes, facet holes, holes, region seeds) mapped by `point`
    and region max volumes multiplied by volume_factor."""
    nodes = [point(p) for p in nodes]
    facets = [(f[0], f[1], [point(h) for h in f[2]]) if len(f) > 2 else f for f in facets]
    holes = [point(h) for h in holes]
    regions = [point(r[:3]) + (r[3], r[4] * volume_factor if r[4] > 0 else r[4]) + tuple(r[5:]) for r in regions]
    return nodes, facets, holes, regions

def rotate_plc(rng, *plc):
    m = random_rotation(rng)
    def rot(p):
        d = [p[k] - 0.5 for k in range(3)]
        return tuple(0.5 + sum(m[i][k] * d[k] for k in range(3)) for i in range(3))
    return map_plc(rot, 1, *plc)

def bend_plc(rng, nodes, facets, holes=(), regions=()):
    size = [1.0] * len(nodes)
    for f in facets:
        ids = [v for poly in f[0] for v in poly]
        lo = [min(nodes[v][k] for v in ids) for k in range(3)]
        hi = [max(nodes[v][k] for v in ids) for k in range(3)]
        d = math.sqrt(sum((hi[k] - lo[k]) ** 2 for k in range(3)))
        for v in ids:
            size[v] = min(size[v], d)
    out = []
    for p, d in zip(nodes, size):
        u = [rng.gauss(0, 1) for _ in range(3)]
        n = math.sqrt(sum(x * x for x in u)) or 1.0
        a = 2e-9 * d * rng.random()
        out.append(tuple(p[k] + a * u[k] / n for k in range(3)))
    return out, facets, holes, regions

def move_far(*plc):
    s, t = 1e-2, (12345.678, -9876.54, 4321.0)
    return map_plc(lambda p: tuple(t[k] + s * (p[k] - 0.5) for k in range(3)), s ** 3, *plc)

if __name__ == '__main__':
    kind, seed, out = sys.argv[1], int(sys.argv[2]), sys.argv[3]
    parts = kind.split('+')
    base, mods = parts[0], parts[1:]
    rng = random.Random(seed * 1000 + list(GENS).index(base))
    r = None
    while r is None:
        r = GENS[base](rng)
    if 'bend' in mods:
        r = bend_plc(random.Random(seed * 1000 + 998), *r)
    if 'rot' in mods:
        r = rotate_plc(random.Random(seed * 1000 + 999), *r)
    if 'far' in mods:
        r = move_far(*r)
    write_poly(out, *r)
