"""Jupyter: one-line reprs of the model's parts and of a result, the HTML table
of a result (what a notebook shows for a cell's last value)."""
from __future__ import annotations

import re
from html.parser import HTMLParser

import numpy as np
import pytest
import skfem

from skfem_mortar import (Cable, ContactPair, Dirichlet, FollowerPressure, MixedSolid, Model,
                          NeoHooke, Result, Solid, StepRecord, TiePair, solve)
from skfem_mortar.contact.surfaces import ContactSurface, RigidPlane

#: a repr is one short line: what a notebook prints for a cell's last value
#: (today's dataclass repr of a result printed 85,000 characters of arrays)
SHORT = 200


def readme_model():
    """The README's model (a cable inflated into a cushion), unsolved."""
    mesh = (skfem.MeshTri.init_tensor(np.linspace(-1.5, 1.5, 25), np.linspace(0.65, 1.4, 7))
            .with_boundaries({"bottom": lambda x: np.isclose(x[1], 0.65),
                              "top": lambda x: np.isclose(x[1], 1.4)}))
    cushion = Solid(mesh, NeoHooke(E=20.0, nu=0.3), element="tri1", name="cushion")
    cable = Cable.between((-1.0, 0.0), (1.0, 0.0), 2.4, 24, EA=50.0, law="svk", name="cable")
    pair = ContactPair(ContactSurface.from_cable(cable, side="left"),
                       ContactSurface.from_solid(cushion, "bottom"), method="mortar",
                       name="contact")
    model = Model([cable, cushion, pair,
                   FollowerPressure(cable, 20.0, side="left", name="pressure"),
                   Dirichlet(cable, cable.support_dofs(), name="supports"),
                   Dirichlet(cushion, cushion.dofs_on("top"), name="clamp")])
    return model, cushion, cable, pair


@pytest.fixture(scope="module")
def solved():
    model, cushion, cable, pair = readme_model()
    return solve(model, n_steps=10), cushion, cable, pair


def one_line(text: str) -> str:
    assert "\n" not in text and len(text) < SHORT, text
    assert "array(" not in text, text  # no states or records inside
    return text


def test_body_reprs_name_their_sizes():
    model, cushion, cable, pair = readme_model()
    s = one_line(repr(cushion))
    assert s.startswith("Solid('cushion', NeoHooke(")
    assert (f"{cushion.n_nodes} nodes" in s and f"{cushion.mesh.nelements} elements" in s
            and f"{cushion.n_dofs} dofs" in s and "tri1" in s and "plane strain" in s)
    c = one_line(repr(cable))
    assert c == "Cable('cable', law svk, open: 25 nodes, 24 elements, 50 dofs)"
    ring = Cable.ring(1.0, 12, law="linear", tension_only=True, name="ring")
    assert one_line(repr(ring)) == \
        "Cable('ring', law linear, tension only, closed: 12 nodes, 12 elements, 24 dofs)"


def test_a_subclass_of_solid_names_its_own_class():
    mesh = skfem.MeshTri.init_tensor(np.linspace(0, 1, 3), np.linspace(0, 1, 3))
    mixed = MixedSolid(mesh, NeoHooke(E=1.0, nu=0.49), name="soft")
    assert one_line(repr(mixed)).startswith("MixedSolid('soft', ")
    small = Solid(mesh, NeoHooke(E=1.0, nu=0.3), kinematics="small", plane="stress")
    assert "small strain, plane stress" in one_line(repr(small))


def test_model_and_pair_reprs_count_their_parts():
    model, cushion, cable, pair = readme_model()
    m = one_line(repr(model))
    assert m == ("Model(6 items: 2 with displacements, 1 with multipliers, 3 loads and "
                 f"constraints; {model.n} unknowns = {model.n_u} displacements + "
                 f"{model.n_lam} multipliers)")
    assert model.n == model.n_u + model.n_lam == 350 + 50 + 25
    p = one_line(repr(pair))
    assert p == ("ContactPair('contact', mortar: slave 'cable_left' (25 nodes) on master "
                 "'cushion_bottom' (25 nodes), 0 active)")
    thin = Model([Cable.between((0, 0), (1, 0), 1.2, 4, name="c")], thickness=0.5)
    assert one_line(repr(thin)).endswith("thickness 0.5)")


def test_pair_repr_with_a_rigid_master_and_a_tie_repr():
    mesh = skfem.MeshQuad.init_tensor(np.linspace(0, 1, 4), np.linspace(0, 1, 3)).with_defaults()
    top = Solid(mesh, NeoHooke(E=1.0, nu=0.3), element="quad1", name="top")
    plane = RigidPlane((0.0, 0.0), (0.0, 1.0))
    pair = ContactPair(ContactSurface.from_solid(top, "bottom"), plane, method="nts")
    assert re.fullmatch(r"ContactPair\('contact', nts: slave 'top_bottom' \(4 nodes\) on master "
                        r"'.+' \(\d+ nodes\), 0 active\)", one_line(repr(pair))), repr(pair)
    low = Solid(skfem.MeshQuad.init_tensor(np.linspace(0, 1, 3), np.linspace(-1, 0, 2))
                .with_defaults(), NeoHooke(E=1.0, nu=0.3), element="quad1", name="low")
    tie = TiePair(ContactSurface.from_solid(top, "bottom"), ContactSurface.from_solid(low, "top"),
                  dual=True, name="glue")
    assert one_line(repr(tie)) == ("TiePair('glue', dual: slave 'top_bottom' (4 nodes) on master "
                                   f"'low_top' (3 nodes), {int(tie.tied.sum())} tied)")


def test_result_repr_is_one_line_with_steps_and_iterations(solved):
    result, _, _, pair = solved
    r = one_line(repr(result))
    its = sum(s.newton_iterations for s in result.steps)
    assert r.startswith(f"Result(converged, 10 steps, {its} Newton iterations, load factor 1, "
                        f"{result.model.n} unknowns, ")
    assert str(result) == r
    assert f"{int(pair.active.sum())} active)" in one_line(repr(pair))  # after the solve


def test_a_failed_result_says_so():
    model, *_ = readme_model()
    rec = StepRecord(0.1 + 0.2, 3, [1.0, 1e-3, 1e-12], cuts=2)
    r = one_line(repr(Result(model, [rec], [model.zeros(), model.zeros()], converged=False)))
    assert r.startswith("Result(not converged, 1 steps, 3 Newton iterations, 2 cuts, "
                        "load factor 0.3, ")


class _Table(HTMLParser):
    """The cells of every row of an HTML table (header rows included)."""

    def __init__(self):
        super().__init__()
        self.rows: list[list[str]] = []
        self._cell: list[str] | None = None

    def handle_starttag(self, tag, attrs):
        if tag == "tr":
            self.rows.append([])
        elif tag in ("td", "th"):
            self._cell = []

    def handle_endtag(self, tag):
        if tag in ("td", "th"):
            self.rows[-1].append("".join(self._cell))
            self._cell = None

    def handle_data(self, data):
        if self._cell is not None:
            self._cell.append(data)


def table(html: str) -> list[list[str]]:
    parser = _Table()
    parser.feed(html)
    return parser.rows


def test_result_html_table_lists_every_step(solved):
    result = solved[0]
    html = result._repr_html_()
    assert html.startswith("<div>") and html.endswith("</div>")
    assert "converged, 10 steps" in html and "linear solves" in html
    rows = table(html)
    assert rows[0] == ["step", "load factor", "Newton iterations", "final residual",
                       "active nodes", "active-set changes", "cuts"]
    assert len(rows) == 1 + len(result.steps)
    for k, (row, s) in enumerate(zip(rows[1:], result.steps)):
        assert row[0] == str(k + 1)
        assert float(row[1]) == pytest.approx(s.load_factor, rel=1e-12)  # 12 digits
        assert int(row[2]) == s.newton_iterations and int(row[4]) == s.n_active
        assert float(row[3]) == pytest.approx(s.residual_norms[-1], rel=1e-2)  # 3 digits


def test_a_long_result_lists_its_first_and_last_steps():
    model, *_ = readme_model()
    n = 3 * Result.HTML_ROWS
    steps = [StepRecord((k + 1) / n, k % 5 + 1, [1.0, 1e-11]) for k in range(n)]
    rows = table(Result(model, steps, [model.zeros()] * (n + 1), converged=True)._repr_html_())
    first, last = Result.HTML_ROWS, Result.HTML_ROWS
    assert len(rows) == 1 + first + 1 + last
    assert [r[0] for r in rows[1:first + 1]] == [str(k + 1) for k in range(first)]
    assert set(rows[first + 1]) == {"\u2026"}
    assert [r[0] for r in rows[-last:]] == [str(k + 1) for k in range(n - last, n)]
    assert rows[-1][1] == "1"


def test_result_plot_is_shown_inline(solved, tmp_path):
    """``Result.plot`` returns the path of its PNG (a ``Path`` still), which a
    notebook shows as the picture (``_repr_png_``)."""
    pytest.importorskip("pyvista")
    from pathlib import Path

    out = solved[0].plot(tmp_path / "result.png", title="README model")
    assert isinstance(out, Path) and out == tmp_path / "result.png"
    png = out._repr_png_()
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) == out.stat().st_size
    assert type(out)(tmp_path / "missing.png")._repr_png_() is None  # then the text repr
