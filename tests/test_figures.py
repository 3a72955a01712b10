"""Pictures that read at a glance (issue 19): what the figure promises, checked on
its artists (no pixel comparison).

A small model is built by hand and drawn at hand-made states (no solve): a
sheared neo-Hookean block held on its left side (both components) and on its
bottom (y only), pushed down on its top by a dead traction, and a straight
cable under it, pinned at both ends and pushed up by a follower pressure; a
contact table (the ``contact_data`` protocol) gives pressures on a few nodes.
"""
import numpy as np
import pytest
import skfem

from skfem_mortar import Cable, Dirichlet, FollowerPressure, Model, NeoHooke, Solid
from skfem_mortar.app.bench import plot_bench
from skfem_mortar.loads.traction import Traction
from skfem_mortar.output.plot import (CONSTANT_SPREAD, PRESSURE_WORDS, colour_ticks,
                                      plot_pressure, relative_spread, render, tick_labels)
from skfem_mortar.output.plot_common import _value
from skfem_mortar.output.plot_geometry import _thin

N_CABLE = 6  # cable elements


def _block(name="block", y0=0.0):
    mesh = (skfem.MeshTri.init_tensor(np.linspace(0.0, 1.0, 4), np.linspace(y0, y0 + 0.5, 3))
            .with_boundaries({"left": lambda x: np.isclose(x[0], 0.0),
                              "bottom": lambda x: np.isclose(x[1], y0),
                              "top": lambda x: np.isclose(x[1], y0 + 0.5)}))
    return Solid(mesh, NeoHooke(E=10.0, nu=0.3), element="tri1", name=name)


def _scene(*extra):
    block = _block()
    X = np.vstack([np.linspace(0.0, 1.0, N_CABLE + 1), np.full(N_CABLE + 1, -0.3)])
    cable = Cable(X, EA=1000.0, law="linear", name="cable")
    items = [block, cable, *extra,
             Dirichlet(block, block.dofs_on("left"), name="clamp"),
             Dirichlet(block, block.dofs_on("bottom", "y"), name="roller"),
             Dirichlet(cable, cable.support_dofs(), name="pins"),
             Traction(block, "top", (0.0, -1.0), name="push"),
             FollowerPressure(cable, 2.0, side="left", name="inflate")]
    model = Model(items)
    z0 = model.zeros()
    z1 = z0.copy()
    Xb = block.X
    u = np.vstack([0.05 * Xb[1] ** 2, -0.02 * Xb[0]])  # a non-uniform shear
    z1[block.offset + block.node_dofs] = u
    return {"model": model, "block": block, "cable": cable, "z0": z0, "z1": z1,
            "bodies": [block, cable, *extra]}


@pytest.fixture(scope="module")
def scene():
    return _scene()


def _stretch(scene, strains):
    """``z1`` with the cable's elements stretched by ``strains`` (along x)."""
    z = scene["z1"].copy()
    cable = scene["cable"]
    L = np.diff(cable.X[0])
    ux = np.concatenate([[0.0], np.cumsum(L * np.asarray(strains))])
    z[cable.offset + cable.node_dofs[0]] = ux
    return z


def _contact(pressure_on):
    """A contact table: slave nodes on the block's bottom, a pressure on a few."""
    x = np.linspace(0.0, 1.0, 4)

    def contact_data(z):
        return {"x": x, "y": np.zeros_like(x), "gap": np.zeros_like(x),
                "pressure": np.asarray(pressure_on, dtype=float)}
    return contact_data


def _draw(scene, z1, contact=None, bodies=None, **kw):
    m = scene["model"]
    return render(bodies or [scene["block"], scene["cable"]], scene["z0"], z1,
                  contact=contact, items=m.items, load_factor=1.0, **kw)


def _keys(fig):
    return [ax for ax in fig.axes if ax.get_gid() == "colour key"]


def _panels(fig):
    return [ax for ax in fig.axes if ax.get_gid() == "panel"]


def _box(fig, artist):
    """An artist's bounding box (with its labels and title) in figure coordinates."""
    bb = artist.get_tightbbox(fig.canvas.get_renderer())
    return bb.transformed(fig.transFigure.inverted())


def _disjoint(a, b):
    return a.x1 <= b.x0 or b.x1 <= a.x0 or a.y1 <= b.y0 or b.y1 <= a.y0


def test_colour_keys_never_overlap():
    # 3 bodies and a contact pair: 4 keys, two rows, titles wrapped in two lines
    scene = _scene(_block("lower block", y0=-1.0))
    fig = _draw(scene, _stretch(scene, np.linspace(0.01, 0.02, N_CABLE)),
                contact=_contact([0.0, 1.0, 3.0, 2.0]), bodies=scene["bodies"])
    keys = _keys(fig)
    assert [k.get_label() for k in keys] == [
        "block: von Mises stress (force/length\u00b2)", "cable tension (force)",
        "lower block: von Mises stress (force/length\u00b2)", PRESSURE_WORDS]
    boxes = [_box(fig, k) for k in keys]
    others = [_box(fig, a) for a in _panels(fig)] + [_box(fig, fig.legends[0])]
    for i, a in enumerate(boxes):
        assert a.x0 >= 0 and a.y0 >= 0 and a.x1 <= 1 and a.y1 <= 1  # inside the figure
        for b in boxes[i + 1:] + others:
            assert _disjoint(a, b), (keys[i].get_label(), a, b)


def test_a_constant_field_is_one_colour_with_its_value(scene):
    z1 = _stretch(scene, np.full(N_CABLE, 0.0158))   # one tension: 15.8
    tension = scene["cable"].output_data(z1)[1]["tension"][0]
    assert relative_spread(tension) < CONSTANT_SPREAD  # the premise
    fig = _draw(scene, z1, contact=_contact([0.0, 5.0, 5.0, 5.0]))
    deformed = _panels(fig)[1]
    (lines,) = [c for c in deformed.collections if c.get_gid() == "cable"]
    assert lines.get_array() is None                          # not colour-mapped
    assert len(np.unique(lines.get_colors(), axis=0)) == 1    # one colour
    (points,) = [c for c in deformed.collections if c.get_gid() == "contact pressure"]
    assert points.get_array() is None and len(np.unique(points.get_facecolors(), axis=0)) == 1
    texts = [t.get_text() for k in _keys(fig) for t in k.texts if t.get_gid() == "constant value"]
    assert len(texts) == 2  # the tension and the pressure
    assert texts[0].startswith(f"{_value(float(np.mean(tension)))} everywhere")
    assert texts[1].startswith("5.000 everywhere")
    # the sheared block is not constant: a colour map with ticks
    (block,) = [c for c in deformed.collections if c.get_gid() == "block"]
    assert block.get_array() is not None and len(_keys(fig)[0].get_xticks()) >= 2


def test_near_constant_tension_has_distinct_tick_labels(scene):
    # the case: a tension from 15.774 to 15.807 read "15.8 15.8 15.8"
    z1 = _stretch(scene, np.linspace(0.015774, 0.015807, N_CABLE))
    tension = scene["cable"].output_data(z1)[1]["tension"][0]
    assert CONSTANT_SPREAD < relative_spread(tension) < 10 * CONSTANT_SPREAD  # the premise
    fig = _draw(scene, z1)
    (key,) = [k for k in _keys(fig) if k.get_label() == "cable tension (force)"]
    labels = [t.get_text() for t in key.get_xticklabels()]
    assert len(labels) >= 2 and len(set(labels)) == len(labels)
    # each label reads its tick (to half a unit of its last digit)
    for text, tick in zip(labels, key.get_xticks()):
        decimals = len(text.split(".")[1]) if "." in text else 0
        assert abs(float(text) - tick) <= 0.5 * 10.0 ** -decimals


@pytest.mark.parametrize("lo, hi", [(15.774, 15.807), (0.0, 8.689), (0.01068, 6.232),
                                    (-1.0, 1.0), (1e-9, 3e-8), (-2e6, 5e6),
                                    (0.1, 0.1003), (9677.0, 10190.0)])
def test_tick_labels_are_distinct_and_read_their_ticks(lo, hi):
    ticks, labels = colour_ticks(lo, hi, n=6)
    assert 2 <= len(ticks) <= 6
    assert np.all((ticks >= lo - 1e-9 * (hi - lo)) & (ticks <= hi + 1e-9 * (hi - lo)))
    assert len(set(labels)) == len(labels)
    step = np.diff(ticks).min()
    # 1e-6 of the spacing: the rule of tick_labels (round ticks read exactly)
    assert np.allclose([float(t) for t in labels], ticks, rtol=0, atol=1e-6 * step)
    assert tick_labels([-1e-17, 0.5, 1.0])[0] == "0.0"  # no "-0.0"


def test_the_pressure_range_starts_at_0(scene):
    fig = _draw(scene, scene["z1"], contact=_contact([0.0, 4.0, 6.5, 5.0]))
    (points,) = [c for c in _panels(fig)[1].collections if c.get_gid() == "contact pressure"]
    assert points.get_clim() == (0.0, 6.5)
    assert len(points.get_offsets()) == 3  # the nodes with a pressure > 0
    (key,) = [k for k in _keys(fig) if k.get_label() == PRESSURE_WORDS]
    assert key.get_xlim()[0] == 0.0 and float(key.get_xticklabels()[0].get_text()) == 0.0
    assert "> 0 compression" in key.get_label() and "max 6.5" in key.get_title()


def test_supports_and_loads_are_marked(scene):
    block, cable = scene["block"], scene["cable"]
    fig = _draw(scene, _stretch(scene, np.full(N_CABLE, 0.01)))
    for ax in _panels(fig):
        marks = [(m.get_marker(), m.get_markerfacecolor(), len(m.get_xdata()))
                 for m in ax.lines if m.get_gid() == "supports"]
        # both components held: filled triangles on the left side (3 nodes), at the
        # cable ends (2); y only: the bottom nodes off the left side (3 of 4), open
        assert sorted(marks) == sorted([("^", "black", 3), ("^", "none", 3), ("^", "black", 2)])
        arrows = [q for q in ax.collections if q.get_gid() == "loads"]
        assert [q.N for q in arrows] == [4, N_CABLE + 1]  # top nodes, cable nodes
    labels = [t.get_text() for t in fig.legends[0].get_texts()]
    assert labels == ["support: x, y held", "support: y held",
                      "load (its direction at the state drawn)"]
    # the arrows point along the nodal loads at the state drawn and stay outside
    # the body: the traction pushes down into the top, its arrows end at the top
    push, inflate = [q for q in _panels(fig)[1].collections if q.get_gid() == "loads"]
    tip = push.get_offsets() + np.column_stack([push.U, push.V])
    top = block.x(scene["z1"])[:, np.isclose(block.X[1], 0.5)].T
    assert np.allclose(np.sort(tip[:, 0]), np.sort(top[:, 0]))
    assert np.all(push.V < 0) and np.allclose(push.U, 0.0)
    # the pressure pushes the (straight) cable up, to its left: arrows end at the nodes
    assert np.all(inflate.V > 0)
    assert np.allclose(inflate.get_offsets()[:, 1] + inflate.V, cable.X[1])


def test_axes_name_the_coordinates(scene):
    for ax in _panels(_draw(scene, scene["z1"])):
        assert (ax.get_xlabel(), ax.get_ylabel()) == ("x", "y")
        assert len(ax.get_xticks()) >= 2 and len(ax.get_yticks()) >= 2
        assert ax.get_aspect() == 1.0  # lengths read alike in x and y


def test_thinning_keeps_markers_apart():
    x = np.column_stack([np.linspace(0.0, 1.0, 401), 0.1 * np.sin(np.linspace(0, 3, 401))])
    keep = _thin(x, 0.05)
    d = np.hypot(*(x[keep][:, None] - x[keep][None]).transpose(2, 0, 1))
    assert d[np.triu_indices(len(keep), 1)].min() >= 0.05
    # every point has a kept one near it: the markers still show the whole support
    # (the half-spacing grid, then the greedy pass: within 2 spacings)
    near = np.hypot(*(x[:, None] - x[keep][None]).transpose(2, 0, 1)).min(axis=1)
    assert near.max() <= 0.1
    assert len(_thin(x[:3], 0.05)) == 1 and len(_thin(x[:0], 0.05)) == 0


def test_bad_input_is_refused(scene):
    with pytest.raises(ValueError, match="lo, hi"):
        colour_ticks(1.0, 1.0)
    with pytest.raises(ValueError, match="window_size"):
        _draw(scene, scene["z1"], window_size=(100, 700))
    with pytest.raises(ValueError, match="contact must be"):
        _draw(scene, scene["z1"], contact=[42])


def _keep_figures(monkeypatch):
    """The figures the line plots would save, kept (and closed) instead."""
    import matplotlib.pyplot as plt

    from skfem_mortar.output import plot_common, plot_lines

    seen = []

    def keep(fig, path):
        seen.append(fig)
        plt.close(fig)
    monkeypatch.setattr(plot_lines, "_save", keep)  # plot_pressure's
    monkeypatch.setattr(plot_common, "_save", keep)  # plot_bench's (imported when called)
    return seen


def test_pressure_plot_starts_at_0(tmp_path, monkeypatch):
    seen = _keep_figures(monkeypatch)
    x = np.linspace(-1, 1, 11)
    curves = [{"method": "mortar", "label": "lf=1", "x": x, "pressure": 2 + 0 * x}]
    plot_pressure(curves, tmp_path / "p.png")
    (ax,) = seen[0].axes
    assert ax.get_ylim()[0] == 0.0 and "> 0 compression" in ax.get_ylabel()


def test_bench_plot_reads_failed_sizes(tmp_path, monkeypatch):
    seen = _keep_figures(monkeypatch)
    ok = [{"status": "ok", "n_dofs": n, "time_per_iteration_s":
           {"bulk": 1e-6 * n, "search": 1e-7 * n, "contact_assembly": 1e-5,
            "solve": 1e-9 * n ** 1.5, "output": 0.0}} for n in (1000, 4000)]
    report = {"method": "mortar", "scenes": {
        "hertz": {"rows": ok + [{"status": "failed: MemoryError"}], "slopes": {"bulk": 1.0}},
        "seed": {"rows": [{"status": "failed: x"}], "slopes": {}}}}
    plot_bench(report, tmp_path / "bench.png")
    hertz, seed = seen[0].axes
    assert "1 of 3 sizes failed" in hertz.get_title()
    labels = [t.get_text() for t in hertz.get_legend().get_texts()]
    assert labels[0] == "bulk assembly (slope 1.00)" and len(labels) == 4  # output: no time
    assert seed.get_legend() is None and "no size ran" in [t.get_text() for t in seed.texts]
