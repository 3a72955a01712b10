"""Kratos' 3D frictionless contact patch tests (``data3d/``) read into our objects,
and each deck's exact answer (Kratos' results against it: ``side_by_side3d.py``).

    import decks3d; model, info = decks3d.build_model("patch_nonmatching", factory)

The decks (:data:`DECKS`; data and source in ``data3d/SOURCE.md``):

* ``patch_matching`` / ``patch_nonmatching``: a foundation block
  ``[0, 8] x [0, 4] x [0, 8]`` (``y`` up) and a punch ``[4, 6] x [4, 6] x [4, 6]``
  on it, both ``hex1`` (``SmallDisplacementElement3D8N``, linear elastic), the
  punch's interface grid matching the foundation's (lines 4, 5, 6) or not (4, 4.7,
  6); a pressure ``p = 1`` (``SurfaceLoadCondition3D4N``, ``SURFACE_LOAD`` of
  modulus 1 along ``-y``) on the punch's top and the foundation's uncovered top,
  rollers (``DISPLACEMENT_BC_*``) holding the rigid modes and nothing else;
  quad4 on quad4 faces.  Slave: the punch (matching), the foundation (non-matching).
* ``simplest_triquad`` / ``simplest_quadtri``: a unit cube of one ``hex1`` under a
  unit cube of 18 ``tet1`` with a gap of 0.001, the hex's bottom and the tets'
  top clamped, the top moved by ``-0.1`` in ``z`` (Kratos' ``HyperElastic3DLaw``):
  tri3 on quad4 faces, the tets (``triquad``) or the hex (``quadtri``) slave.

Exact answers (:func:`exact_answer`).  Patch decks: the state is uniaxial stress
``sigma_yy = -s`` in both bodies (the rollers leave the lateral strain
``e = nu s / E`` free).  Kratos moves its mesh and integrates ``SURFACE_LOAD``
over the *current* face, so the load on a top face of reference area ``A`` is
``p A (1 + e)^2``; its small-displacement elements carry ``s A`` through the
reference section, so ``s = p (1 + nu s / E)^2`` (solved by fixed point, the
map's slope ``2 nu p / E (1 + e)`` is 0.006 and 0.0008 here).  The interface
moves by ``u_y = -s H / E`` (``H = 4`` the foundation's height), and the contact
traction, per *current* area as Kratos' mortar integrals measure it, is
``p`` itself: the force ``p A (1 + e)^2`` over the current area ``A (1 + e)^2``.
One reservation, on ``patch_matching`` only: its foundation's supports (``x``
held at (4, 0, 4) and (0, 0, 8)) turn the block by the linearized rotation ``w =
e`` about ``y``, which a moving mesh sees as a stretch of the top by ``(1 + e)^2 +
w^2`` while the punch's supports leave it unturned, so with small-strain
elements that deck has no uniform solution at the level ``w^2 = 1.6e-7``
(measured on the foundation alone: ``test_kratos3d_tools.py``); with
finite-strain elements rotations are rigid and it has.
Simplest decks: no closed form on one hex; the continuum problem is symmetric
about the mid-plane of the closed gap (same material and height, both ends
clamped, frictionless interface: the shear stress is odd in the mirror and
vanishes there), so the interface ends at ``z = -(0.1 - 0.001) / 2`` (the lower
face's ``u_z = -0.0495``, the upper face's ``-0.0505``) in the continuum limit
only: Kratos' values are reported against it as a discretization error, not a
patch-test failure.

Our objects (:func:`bodies`, :func:`build_model`): each part a
:class:`~skfem_mortar.Solid` on ``MeshHex1``/``MeshTet1`` of its own nodes (hexes
renumbered from Kratos' (= VTK's) vertex order to scikit-fem's, tetrahedra turned
positive), the Dirichlet data per component from the deck's processes, the load
as :class:`~skfem_mortar.loads.pressure3d.FollowerPressure3D` (a pressure on the
current area, as Kratos applies it) and the two contact faces as outward
tri3/quad4 node arrays (:func:`~skfem_mortar.contact.boundary_cells.boundary_cells`).
"""
from __future__ import annotations

import json
import os
import re
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
DATA = os.path.join(HERE, "data3d")

#: deck -> (parameters stem, mesh stem, materials file, Kratos' stored results stem)
DECKS = {
    "patch_matching": ("3D_contact_patch_matching_test", "3D_contact_patch_matching_test",
                       "3D_contact_patch_matching_test_materials.json",
                       "3D_contact_patch_matching_test_results"),
    "patch_nonmatching": ("3D_contact_patch_nonmatching_test",
                          "3D_contact_patch_nonmatching_test",
                          "3D_contact_patch_nonmatching_test_materials.json",
                          "3D_contact_patch_nonmatching_test_results"),
    "simplest_triquad": ("3D_contact_simplest_patch_matching_triquad_test",
                         "3D_contact_simplest_patch_matching_triquad_test",
                         "3D_contact_simplest_patch_matching_test_materials.json",
                         "3D_contact_simplest_patch_matching_triquad_test_results"),
    "simplest_quadtri": ("3D_contact_simplest_patch_matching_quadtri_test",
                         "3D_contact_simplest_patch_matching_triquad_test",
                         "3D_contact_simplest_patch_matching_test_materials.json",
                         "3D_contact_simplest_patch_matching_quadtri_test_results"),
}
#: Kratos' (= VTK's) hexahedron vertex order to scikit-fem's (skfem.io.meshio's map)
HEX_KRATOS_TO_SKFEM = np.array([0, 4, 3, 1, 7, 5, 2, 6])
_ELEMENT_KINDS = {"3D8N": "hex1", "3D4N": "tet1"}


@dataclass
class Mdpa:
    """A Kratos ``.mdpa`` file: node ids and coordinates, element and condition
    blocks (Kratos name, ids, node ids, property ids) and sub-model parts (name ->
    ``{"nodes", "elements", "conditions"}`` id arrays)."""
    node_ids: np.ndarray
    X: np.ndarray
    elements: list = field(default_factory=list)    # (kratos name, ids, conn, props)
    conditions: list = field(default_factory=list)
    parts: dict = field(default_factory=dict)

    def coords(self, ids: np.ndarray) -> np.ndarray:
        """Coordinates (n, 3) of the nodes ``ids``."""
        pos = np.searchsorted(self.node_ids, ids)
        if np.any(pos >= self.node_ids.size) or np.any(self.node_ids[pos] != ids):
            raise ValueError("ids must be node ids of the deck")
        return self.X[pos]

    def elements_of(self, part: str) -> tuple[str, np.ndarray]:
        """The kind (``hex1``/``tet1``) and Kratos connectivity (n_e, k) of the
        elements of sub-model part ``part`` (one element kind per part)."""
        want = set(self.parts[part]["elements"].tolist())
        kinds, rows = set(), []
        for name, ids, conn, _ in self.elements:
            keep = np.isin(ids, list(want))
            if keep.any():
                kinds.add(_ELEMENT_KINDS[name[-4:]])
                rows.append(conn[keep])
        if len(kinds) != 1:
            raise ValueError(f"part {part!r} must hold elements of one kind, got {kinds}")
        return kinds.pop(), np.concatenate(rows)


def _table(lines: list[str], ncol: int | None = None) -> np.ndarray:
    rows = [ln.split("//")[0].split() for ln in lines]
    rows = [r for r in rows if r]
    return np.array(rows, dtype=float) if rows else np.zeros((0, ncol or 1))


def read_mdpa(path: str) -> Mdpa:
    """Read a Kratos ``.mdpa`` (nodes, elements, conditions, sub-model parts)."""
    with open(path) as f:
        text = f.read().splitlines()
    blocks: list[tuple[str, str, list[str]]] = []
    stack: list[tuple[str, str, list[str]]] = []
    for line in text:
        s = line.split("//")[0].strip()
        m = re.match(r"Begin\s+(\w+)\s*(\S*)", s)
        if m:
            stack.append((m.group(1), m.group(2), []))
            continue
        if s.startswith("End"):
            blocks.append(stack.pop())
            continue
        if stack:
            stack[-1][2].append(s)
    return _assemble(blocks)


def _assemble(blocks) -> Mdpa:
    nodes = next(b for b in blocks if b[0] == "Nodes")
    t = _table(nodes[2], 4)
    order = np.argsort(t[:, 0])
    deck = Mdpa(t[order, 0].astype(int), t[order, 1:4])
    current: dict[str, np.ndarray] = {}
    for kind, name, lines in blocks:
        if kind in ("Elements", "Conditions"):
            a = _table(lines).astype(int)
            (deck.elements if kind == "Elements" else deck.conditions).append(
                (name, a[:, 0], a[:, 2:], a[:, 1]))
        elif kind.startswith("SubModelPart") and kind != "SubModelPart":
            key = kind[len("SubModelPart"):].lower()
            current[key] = _table(lines).astype(int).ravel()
        elif kind == "SubModelPart":
            deck.parts[name] = {k: current.get(k, np.zeros(0, int))
                                for k in ("nodes", "elements", "conditions")}
            current = {}
    return deck


@dataclass
class Deck:
    """A deck read whole: the mesh, its parameters' Dirichlet data (``(part,
    constrained (3,), value (3,))``), loads (``(part, traction vector (3,))``),
    the contact part and its slave part, and each body part's material
    (``(law, E, nu)``)."""
    name: str
    mdpa: Mdpa
    dirichlet: list
    loads: list
    contact_part: str
    slave_part: str
    materials: dict


def _strip(part: str) -> str:
    return part.split(".", 1)[1] if part.startswith("Structure.") else part


def read_deck(name: str) -> Deck:
    """The deck ``name`` (a key of :data:`DECKS`) from ``data3d/``.

    Raises
    ------
    ValueError
        ``name`` not a key of :data:`DECKS`.
    """
    if name not in DECKS:
        raise ValueError(f"name must be one of {sorted(DECKS)}, got {name!r}")
    stem, mesh, mat, _ = DECKS[name]
    mdpa = read_mdpa(os.path.join(DATA, mesh + ".mdpa"))
    with open(os.path.join(DATA, stem + "_parameters.json")) as f:
        proc = json.load(f)["processes"]
    dirichlet, loads = [], []
    for p in (q["Parameters"] for q in proc.get("constraints_process_list", [])):
        fixed = p.get("constrained", [True, True, True])
        value = [float(v) if not isinstance(v, str) else float(v.replace("*t", ""))
                 for v in p["value"]]   # "-1.0*t": the value at t = 1
        dirichlet.append((_strip(p["model_part_name"]), np.array(fixed, bool), np.array(value)))
    for p in (q["Parameters"] for q in proc.get("loads_process_list", [])):
        if p["variable_name"] != "SURFACE_LOAD":
            raise ValueError(f"deck {name!r}: load {p['variable_name']} is not read")
        loads.append((_strip(p["model_part_name"]),
                      float(p["modulus"]) * np.asarray(p["direction"], float)))
    contact = proc["contact_process_list"][0]["Parameters"]
    with open(os.path.join(DATA, mat)) as f:
        props = json.load(f)["properties"]
    materials = {}
    for q in props:
        var = q["Material"]["Variables"]
        materials[_strip(q["model_part_name"])] = (
            q["Material"]["constitutive_law"]["name"], float(var["YOUNG_MODULUS"]),
            float(var["POISSON_RATIO"]))
    return Deck(name, mdpa, dirichlet, loads, contact["contact_model_part"]["0"][0],
                contact["assume_master_slave"]["0"][0], materials)


def skfem_mesh(X: np.ndarray, kind: str, conn: np.ndarray) -> Any:
    """A ``MeshHex1`` (Kratos' vertex order turned into scikit-fem's) or
    ``MeshTet1`` (each tetrahedron turned positive by swapping its last two
    vertices where its volume is negative) on the points ``X`` (n, 3), ``conn``
    indexing ``X``."""
    import skfem
    if kind == "hex1":
        return skfem.MeshHex1(np.ascontiguousarray(X.T), np.ascontiguousarray(
            conn[:, HEX_KRATOS_TO_SKFEM].T))
    a, b, c, d = (X[conn[:, i]] for i in range(4))
    neg = np.einsum("ij,ij->i", np.cross(b - a, c - a), d - a) < 0
    conn = conn.copy()
    conn[neg, 2:] = conn[neg, 3:1:-1]
    return skfem.MeshTet1(np.ascontiguousarray(X.T), np.ascontiguousarray(conn.T))


@dataclass
class Part:
    """A body part of a deck on its own mesh: Kratos node ids of its vertices
    (``ids[k]`` is vertex ``k``), its element kind and scikit-fem mesh, its material."""
    name: str
    ids: np.ndarray
    kind: str
    mesh: Any
    material: tuple

    def local(self, node_ids: np.ndarray) -> np.ndarray:
        """Vertex indices of those of ``node_ids`` that belong to this part."""
        node_ids = np.asarray(node_ids)
        return np.searchsorted(self.ids, node_ids[np.isin(node_ids, self.ids)])

    def faces_on(self, node_ids: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The boundary facets whose vertices all lie in ``node_ids``: their
        indices and their outward cells (tri3/quad4, vertex indices)."""
        from skfem_mortar.contact.boundary_cells import boundary_cells
        mine = np.zeros(self.ids.size, bool)
        mine[self.local(node_ids)] = True
        bf = self.mesh.boundary_facets()
        facets = bf[mine[self.mesh.facets[:, bf]].all(axis=0)]
        conn, _ = boundary_cells(self.mesh, facets)
        return facets, conn


def parts(deck: Deck) -> dict[str, Part]:
    """Each body part of ``deck`` (the parts its materials name) on its own mesh."""
    out = {}
    for name, material in deck.materials.items():
        kind, conn = deck.mdpa.elements_of(name)
        ids = np.unique(conn)
        out[name] = Part(name, ids, kind, skfem_mesh(deck.mdpa.coords(ids), kind,
                                                     np.searchsorted(ids, conn)), material)
    return out


def _facets_of(part: Part, cells: np.ndarray) -> np.ndarray:
    """Facet indices of ``part.mesh`` with the vertices of each row of ``cells``
    (Kratos node ids, all of this part)."""
    key = {tuple(col): i for i, col in enumerate(np.sort(part.mesh.facets, axis=0).T)}
    local = np.sort(part.local(cells.ravel()).reshape(cells.shape), axis=1)
    return np.array([key[tuple(r)] for r in local], dtype=int)


def law(material: tuple) -> Any:
    """Our material for Kratos' ``(law, E, nu)``: ``LinearElastic3DLaw`` ->
    :class:`~skfem_mortar.LinearElastic` (small strain, as Kratos' small-displacement
    elements evaluate it), ``HyperElastic3DLaw`` (compressible neo-Hooke) ->
    :class:`~skfem_mortar.NeoHooke`."""
    from skfem_mortar import LinearElastic, NeoHooke
    name, E, nu = material
    laws = {"LinearElastic3DLaw": LinearElastic, "HyperElastic3DLaw": NeoHooke}
    if name not in laws:
        raise ValueError(f"material law must be one of {sorted(laws)}, got {name!r}")
    return laws[name](E=E, nu=nu)


@dataclass
class Face:
    """A contact face of a deck: its body, the Kratos node ids of its vertices and
    its outward cells (``conn``, body vertex indices; tri3 or quad4)."""
    body: Any
    node_ids: np.ndarray
    conn: np.ndarray
    cell: str


def build_model(deck: Deck | str,
                contact_pair_factory: Callable[[Face, Face], Any] | None
                ) -> tuple[Any, dict]:
    """Our model of ``deck``: its bodies, Dirichlet data, load and the contact pair
    ``contact_pair_factory(slave, master)`` (two :class:`Face`; the slave as the
    deck's ``assume_master_slave`` names it; ``None``: no pair, the model of the
    bodies alone, to check the reading).

    Returns
    -------
    model : skfem_mortar.Model
    info : dict
        ``parts`` (name -> :class:`Part`), ``bodies`` (name -> Solid), ``slave``
        and ``master`` (:class:`Face`).
    """
    from skfem_mortar import Dirichlet, Model, Solid
    from skfem_mortar.loads.pressure3d import FollowerPressure3D
    deck = read_deck(deck) if isinstance(deck, str) else deck
    ps = parts(deck)
    bodies = {n: Solid(p.mesh, law(p.material), element=p.kind, name=n) for n, p in ps.items()}
    items: list = list(bodies.values())
    for part, fixed, value in deck.dirichlet:
        for n, p in ps.items():
            nodes = p.local(deck.mdpa.parts[part]["nodes"])
            for c in np.flatnonzero(fixed) if nodes.size else []:
                items.append(Dirichlet(bodies[n], nodes=nodes, component=int(c),
                                       value=float(value[c]), name=f"{part}_{n}_{'xyz'[c]}"))
    for part, traction in deck.loads:
        cond = {int(i) for i in deck.mdpa.parts[part]["conditions"]}
        cells = np.concatenate([conn[np.isin(ids, list(cond))]
                                for _, ids, conn, _ in deck.mdpa.conditions])
        for n, p in ps.items():
            mine = np.isin(cells, p.ids).all(axis=1)
            if mine.any():   # the traction is along -n on these flat faces: a pressure
                items.append(FollowerPressure3D(bodies[n], float(np.linalg.norm(traction)),
                                                _facets_of(p, cells[mine]), name=f"load_{n}"))
    faces = {}
    for n, p in ps.items():
        _, conn = p.faces_on(deck.mdpa.parts[deck.contact_part]["nodes"])
        faces[n] = Face(bodies[n], p.ids[np.unique(conn)], conn,
                        "tri3" if conn.shape[1] == 3 else "quad4")
    master = next(n for n in ps if n != deck.slave_part)
    if contact_pair_factory is not None:
        items.append(contact_pair_factory(faces[deck.slave_part], faces[master]))
    return Model(items), {"parts": ps, "bodies": bodies,
                                   "slave": faces[deck.slave_part], "master": faces[master]}


def exact_answer(deck: Deck | str) -> dict:
    """The exact answer of ``deck`` (module docstring).

    Patch decks: ``{"kind": "patch", "p", "s", "lateral_strain", "pressure"
    (= p, per current area), "pressure_reference" (= s), "u_interface"
    (= -s H / E, the normal displacement of the contact nodes), "axis": 1}``, with
    ``s = p (1 + nu s / E)^2`` by fixed point to round-off.  Simplest decks:
    ``{"kind": "continuum", "u_interface": -(d - g) / 2, ... "axis": 2}``
    (``d`` the prescribed closure, ``g`` the initial gap), the continuum's
    interface position only.
    """
    deck = read_deck(deck) if isinstance(deck, str) else deck
    (_, E, nu), = set(deck.materials.values())
    if deck.loads:
        p = float(np.linalg.norm(deck.loads[0][1]))
        s = p
        for _ in range(100):
            s_new = p * (1.0 + nu * s / E) ** 2
            if abs(s_new - s) <= 1e-16 * s:
                break
            s = s_new
        X = deck.mdpa.coords(deck.mdpa.parts[deck.contact_part]["nodes"])
        H = float(X[:, 1].mean() - deck.mdpa.X[:, 1].min())   # the foundation's height
        return {"kind": "patch", "p": p, "s": s, "lateral_strain": nu * s / E,
                "pressure": p, "pressure_reference": s, "u_interface": -s * H / E, "axis": 1}
    closure = -min(v[2] for _, _, v in deck.dirichlet)
    Z = deck.mdpa.coords(deck.mdpa.parts[deck.contact_part]["nodes"])[:, 2]
    gap = float(Z.max() - Z.min())
    return {"kind": "continuum", "closure": closure, "gap": gap,
            "u_interface": -(closure - gap) / 2, "u_interface_upper": -(closure + gap) / 2,
            "axis": 2}
