"""Uniformly refined copies of Kratos' ``hertz_simple`` test mesh (1x, 2x, 4x).

    python benchmarks/kratos/make_meshes.py --out DIR [--levels 1 2 4]

writes ``DIR/hertz_simple_<k>x.mdpa``.  ``1x`` is the test's mesh as stored in
``data/`` (copied byte for byte); ``2x`` splits every element of it once,
``4x`` splits the ``2x`` mesh again:

* every quadrilateral ``(a, b, c, d)`` becomes four, through its edge
  midpoints and its centre (the mean of its corners), in the same orientation:
  ``(a, m_ab, o, m_da)``, ``(m_ab, b, m_bc, o)``, ``(o, m_bc, c, m_cd)``,
  ``(m_da, o, m_cd, d)``; an edge's midpoint is one node shared by both its
  elements;
* every two-node condition ``(a, b)`` (the line load on the flat face) becomes
  ``(a, m_ab)``, ``(m_ab, b)``;
* the midpoint of a boundary edge of the half cylinder whose two ends lie on
  its circle (centre ``(0, 9)``, radius ``R = 8``, checked against the mesh)
  is moved radially onto the circle;
* sub-model parts: one holding elements or conditions gets their children and
  exactly the nodes of those; one holding nodes only (``Contact_Part``,
  ``DISPLACEMENT_bc_fix``) gets, besides its nodes, the midpoint of every
  boundary edge of the mesh whose two ends it holds.

Node ids of the coarse mesh are kept, new nodes are numbered after them;
elements and conditions are renumbered from 1 in the order of their parents.
The file is written in the layout of the original (``Begin Nodes`` ...
``Begin SubModelPart``), property ids kept.
"""
from __future__ import annotations

import argparse
import os
import shutil
import sys
from dataclasses import dataclass, field

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
SOURCE = os.path.join(HERE, "data", "hertz_simple_test.mdpa")
#: the half cylinder's circle in the test mesh: centre and radius
CENTRE = np.array([0.0, 9.0])
RADIUS = 8.0
#: a node lies on the circle when its distance from the centre is within this
#: of RADIUS: the mdpa prints coordinates to 5 decimals (round-off <= 7e-6 in
#: the distance), while the nearest nodes off the circle are ~1e-2 inside
ON_CIRCLE_TOL = 1e-4


@dataclass
class Block:
    """An ``Elements`` or ``Conditions`` block: its header line, ids, property
    ids and connectivity (``(n, k)`` node ids)."""
    kind: str
    header: str
    ids: np.ndarray
    props: np.ndarray
    conn: np.ndarray


@dataclass
class SubModelPart:
    header: str
    nodes: list[int]
    elements: list[int]
    conditions: list[int]


@dataclass
class Mdpa:
    preamble: str                       # everything before "Begin Nodes"
    nodes: dict[int, tuple[float, float, float]]
    blocks: list[Block]
    parts: list[SubModelPart] = field(default_factory=list)


def read_mdpa(path: str) -> Mdpa:
    """Parse the parts of an mdpa file that the test mesh uses."""
    with open(path) as f:
        lines = f.read().split("\n")
    i = next(k for k, ln in enumerate(lines) if ln.startswith("Begin Nodes"))
    mesh = Mdpa("\n".join(lines[:i]) + "\n", {}, [])
    k = i + 1
    while not lines[k].startswith("End Nodes"):
        f = lines[k].split()
        mesh.nodes[int(f[0])] = (float(f[1]), float(f[2]), float(f[3]))
        k += 1
    while k < len(lines):
        ln = lines[k]
        if ln.startswith("Begin Elements") or ln.startswith("Begin Conditions"):
            kind = ln.split()[1]
            rows = []
            k += 1
            while not lines[k].startswith("End " + kind):
                rows.append([int(v) for v in lines[k].split()])
                k += 1
            a = np.array(rows, dtype=np.int64)
            mesh.blocks.append(Block(kind, ln, a[:, 0], a[:, 1], a[:, 2:]))
        elif ln.startswith("Begin SubModelPart "):
            part = SubModelPart(ln, [], [], [])
            target = None
            k += 1
            while not lines[k].startswith("End SubModelPart"):
                s = lines[k].strip()
                if s.startswith("Begin SubModelPart"):
                    target = {"Nodes": part.nodes, "Elements": part.elements,
                              "Conditions": part.conditions}[s.split()[1][len("SubModelPart"):]]
                elif s.startswith("End SubModelPart"):
                    target = None
                elif s:
                    if target is None:
                        raise ValueError(f"unexpected line in {ln!r}: {s!r}")
                    target.append(int(s))
                k += 1
            mesh.parts.append(part)
        k += 1
    return mesh


def _edges(conn: np.ndarray) -> np.ndarray:
    """The edges ``(n, nv, 2)`` of polygons ``conn`` (``(n, nv)``), in order."""
    return np.stack([conn, np.roll(conn, -1, axis=1)], axis=-1)


def boundary_edges(mesh: Mdpa) -> set[tuple[int, int]]:
    """Edges (sorted node pairs) that belong to exactly one element."""
    count: dict[tuple[int, int], int] = {}
    for b in mesh.blocks:
        if b.kind != "Elements":
            continue
        for a, c in _edges(b.conn).reshape(-1, 2):
            key = (min(a, c), max(a, c))
            count[key] = count.get(key, 0) + 1
    return {e for e, n in count.items() if n == 1}


def _on_circle(xy: np.ndarray) -> np.ndarray:
    return np.abs(np.hypot(*(xy - CENTRE).T) - RADIUS) < ON_CIRCLE_TOL


def refine(mesh: Mdpa) -> Mdpa:
    """Split every quadrilateral into four and every line condition into two
    (module docstring); arc midpoints moved onto the circle."""
    nodes = dict(mesh.nodes)
    xy = lambda n: np.array(nodes[n][:2])  # noqa: E731
    next_id = max(nodes) + 1
    bnd = boundary_edges(mesh)
    mid: dict[tuple[int, int], int] = {}

    def midpoint(a: int, c: int) -> int:
        nonlocal next_id
        key = (min(a, c), max(a, c))
        if key not in mid:
            p = 0.5 * (xy(a) + xy(c))
            if key in bnd and _on_circle(np.array([xy(a), xy(c)])).all():
                v = p - CENTRE
                p = CENTRE + RADIUS * v / np.hypot(*v)
            nodes[next_id] = (float(p[0]), float(p[1]), 0.0)
            mid[key] = next_id
            next_id += 1
        return mid[key]

    blocks, children = [], {}
    counters = {"Elements": 1, "Conditions": 1}
    for b in mesh.blocks:
        rows_conn, rows_prop, rows_id = [], [], []
        for eid, prop, c in zip(b.ids, b.props, b.conn):
            c = [int(v) for v in c]
            if len(c) == 4:
                a, bb, cc, d = c
                mab, mbc, mcd, mda = (midpoint(a, bb), midpoint(bb, cc),
                                      midpoint(cc, d), midpoint(d, a))
                o = next_id
                nodes[o] = tuple(float(v) for v in np.mean([xy(n) for n in c], axis=0)) + (0.0,)
                next_id += 1
                new = [(a, mab, o, mda), (mab, bb, mbc, o), (o, mbc, cc, mcd), (mda, o, mcd, d)]
            elif len(c) == 2:
                m = midpoint(*c)
                new = [(c[0], m), (m, c[1])]
            else:
                raise ValueError(f"{b.kind} {eid}: {len(c)} nodes; only 4-node quadrilaterals "
                                 "and 2-node lines are refined")
            ids = list(range(counters[b.kind], counters[b.kind] + len(new)))
            counters[b.kind] += len(new)
            children[(b.kind, int(eid))] = ids
            rows_conn += new
            rows_prop += [int(prop)] * len(new)
            rows_id += ids
        blocks.append(Block(b.kind, b.header, np.array(rows_id), np.array(rows_prop),
                            np.array(rows_conn)))
    out = Mdpa(mesh.preamble, nodes, blocks)
    conn_of = {(b.kind, int(i)): c for b in blocks for i, c in zip(b.ids, b.conn)}
    for part in mesh.parts:
        els = [c for e in part.elements for c in children[("Elements", e)]]
        cos = [c for e in part.conditions for c in children[("Conditions", e)]]
        if els or cos:
            ns = sorted({int(n) for c in els for n in conn_of[("Elements", c)]}
                        | {int(n) for c in cos for n in conn_of[("Conditions", c)]})
        else:
            held = set(part.nodes)
            ns = sorted(held | {mid[e] for e in bnd if e[0] in held and e[1] in held})
        out.parts.append(SubModelPart(part.header, ns, els, cos))
    return out


def write_mdpa(mesh: Mdpa, path: str) -> None:
    """Write ``mesh`` in the layout of the test's mdpa file."""
    out = [mesh.preamble.rstrip("\n") + "\n", "Begin Nodes"]
    for n in sorted(mesh.nodes):
        x, y, z = mesh.nodes[n]
        out.append(f"{n:6d} {x:16.10f} {y:16.10f} {z:16.10f}")
    out += ["End Nodes", ""]
    for b in mesh.blocks:
        out.append(b.header)
        for i, p, c in zip(b.ids, b.props, b.conn):
            out.append(f"{i:10d} {p:10d} " + " ".join(f"{v:10d}" for v in c))
        out += ["End " + b.kind, ""]
    for part in mesh.parts:
        out.append(part.header)
        for name, ids in (("Nodes", part.nodes), ("Elements", part.elements),
                          ("Conditions", part.conditions)):
            out.append(f"    Begin SubModelPart{name}")
            out += [f"{v:10d}" for v in ids]
            out.append(f"    End SubModelPart{name}")
        out.append("End SubModelPart")
    with open(path, "w") as f:
        f.write("\n".join(out) + "\n")


def check(mesh: Mdpa) -> dict:
    """Consistency of a mesh: every element and condition node exists, every
    sub-model part's nodes exist, the quadrilaterals are positively oriented,
    and the contact arc lies on the circle. Returns counts."""
    ids = set(mesh.nodes)
    for b in mesh.blocks:
        if not set(b.conn.ravel().tolist()) <= ids:
            raise ValueError(f"{b.header}: unknown nodes")
        if b.conn.shape[1] == 4:
            p = np.array([[mesh.nodes[n][:2] for n in row] for row in b.conn])
            x, y = p[..., 0], p[..., 1]
            area = 0.5 * (x * np.roll(y, -1, 1) - np.roll(x, -1, 1) * y).sum(axis=1)
            if not (area > 0).all():
                raise ValueError(f"{b.header}: {int((area <= 0).sum())} elements not "
                                 "counter-clockwise")
    for part in mesh.parts:
        if not set(part.nodes) <= ids:
            raise ValueError(f"{part.header}: unknown nodes")
    contact = next(p for p in mesh.parts if "Contact_Part" in p.header)
    cxy = np.array([mesh.nodes[n][:2] for n in contact.nodes])
    arc = cxy[cxy[:, 1] > 1.0 + 1e-9]   # the plate's top is y = 1
    if not _on_circle(arc).all():
        raise ValueError("contact nodes of the cylinder off its circle")
    return {"nodes": len(mesh.nodes),
            "elements": int(sum(len(b.ids) for b in mesh.blocks if b.kind == "Elements")),
            "contact_nodes": len(contact.nodes), "contact_arc_nodes": int(len(arc))}


def make(out_dir: str, levels=(1, 2, 4)) -> dict[int, str]:
    """Write ``hertz_simple_<k>x.mdpa`` for each level ``k`` (a power of 2) into
    ``out_dir``; returns ``{k: path}``."""
    for k in levels:
        if k < 1 or k & (k - 1):
            raise ValueError(f"levels must be powers of 2 (1, 2, 4, ...), got {k}")
    os.makedirs(out_dir, exist_ok=True)
    paths, mesh, k = {}, read_mdpa(SOURCE), 1
    while k <= max(levels):
        if k in levels:
            path = os.path.join(out_dir, f"hertz_simple_{k}x.mdpa")
            if k == 1:
                shutil.copyfile(SOURCE, path)
            else:
                write_mdpa(mesh, path)
            paths[k] = path
        k *= 2
        if k <= max(levels):
            mesh = refine(mesh)
    return paths


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", required=True, help="directory for the .mdpa files")
    ap.add_argument("--levels", type=int, nargs="+", default=[1, 2, 4],
                    help="refinement factors, powers of 2 (default 1 2 4)")
    a = ap.parse_args(argv)
    for k, path in make(a.out, tuple(a.levels)).items():
        print(f"{k}x: {path} {check(read_mdpa(path))}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
