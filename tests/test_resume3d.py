"""Kill-and-resume of a 3D contact run (issue 38: "kill-and-resume of a 3D run gives the
uninterrupted frames and metrics to the last bit"), as ``test_kill_resume`` does it in
2D: the run through the runner (``run_scene`` with ``--out``) once uninterrupted, then
killed at a seeded random rename in the checkpoint write, one in the frame output and
one anywhere, and resumed (:func:`resume_tools.assert_resumes`).

Two scenes, built here as :class:`~skfem_mortar.scenes.Scene` objects that
``run_scene`` finds by name (``get_scene`` patched for these names): the runner's
whole path (checkpoint, restart, frames, ``contact.csv``, summary) runs unchanged.

* ``blocks``: patch3d's two blocks (``scenes/_patch3d.py``) with their contact pair,
  as the scene registers it: tet1 upper on hex1 lower with the lower block slave (its
  uncovered nodes without master) with NTS and mortar-dual, hex1 on hex1 with the
  upper block slave with mortar;
* ``sphere``: a hex1 block (4 x 4 x 2) pushed up into a rigid sphere with NTS, the
  contact zone growing over the steps (``test_nts3d``'s resume model).

What a resume must restore here is the state, the step history and the controller:
with NTS, the pair's own checkpointed state (the converged active set) is rebuilt
by its initial active set at the restored state (``lam - c g >= 0`` holds exactly
on the converged set), so these runs resume bit for bit even with the pair's
``load_state_dict`` made a no-op (measured).

Three load steps each.

Tolerance: ``resume_tools.RTOL`` (1e-10; its docstring: a resumed PARDISO run repeats
the solves up to the analysis' round-off).  The runs below meet it with differences
of exactly 0 (``test_the_resumed_3d_run_is_bit_for_bit`` compares the metrics, the
residual norms, every frame's arrays and ``contact.csv`` exactly).
"""
from __future__ import annotations

import zlib
from pathlib import Path

import numpy as np
import pytest
import skfem
from resume_tools import assert_resumes, checkpoint_moments, frame_moments

import skfem_mortar.app.runner as runner
from skfem_mortar import Dirichlet, NeoHooke, Solid
from skfem_mortar.contact.pair import ContactPair
from skfem_mortar.contact.rigid3d import RigidSphere
from skfem_mortar.contact.surfaces import ContactSurface
from skfem_mortar.core.model import Model
from skfem_mortar.loads.traction import Traction
from skfem_mortar.output.io import read_series
from skfem_mortar.scenes import METHODS, Param, Scene, Setup
from skfem_mortar.scenes.patch3d import SCENE as PATCH3D


def _sphere(params: dict, method: str | None = None) -> Setup:
    """A block [0, 1]^2 x [0, 1/2] pushed by a traction on its bottom into the rigid
    sphere of radius 1/2 centred at (1/2, 1/2, 1), rollers on its mid-planes."""
    t = np.linspace(0.0, 1.0, 5)
    mesh = skfem.MeshHex.init_tensor(t, t, np.linspace(0.0, 0.5, 3)).with_boundaries(
        {"bottom": lambda x: x[2] < 1e-9, "top": lambda x: x[2] > 0.5 - 1e-9})
    block = Solid(mesh, NeoHooke(E=1.0, nu=0.3), "hex1", name="block")
    pair = ContactPair(ContactSurface.from_solid(block, "top"),
                       RigidSphere((0.5, 0.5, 1.0), 0.5, refine=2), method=method or "nts")
    X = block.mesh.p
    rollers = [Dirichlet(block, nodes=np.flatnonzero(np.abs(X[k] - 0.5) < 1e-9), component=k,
                         name=f"roller_{k}") for k in (0, 1)]
    push = Traction(block, "bottom", (0.0, 0.0, float(params["push"])), name="push")
    model = Model([block, pair, push, *rollers], geometry="3d")

    def metrics(result) -> dict:
        p = pair.pressure_and_gap(result.z)[0]
        return {"pressure_max": float(p.max()), "n_active": int(pair.active.sum()),
                "contact_force": [float(f) for f in pair.total_force(result.z)]}

    return Setup(model=model, metrics=metrics)


SCENES = {"blocks3d_resume_test": Scene(
              name="blocks3d_resume_test", summary="patch3d's blocks (test)", params=PATCH3D.params,
              build=PATCH3D.build, methods=METHODS, default_steps=3,
              estimate_dofs=PATCH3D.estimate_dofs,
              sizes=("n_lower", "n_upper")),
          "sphere3d_resume_test": Scene(
              name="sphere3d_resume_test", summary="a block pushed into a sphere (test)",
              params=(Param("push", 0.05, "traction on the block's bottom", float),),
              build=_sphere, methods=METHODS, default_steps=3)}

BLOCKS, SPHERE = SCENES
CASES = [(BLOCKS, "nts", {"element": "tet1/hex1", "n_lower": 4, "n_upper": 2,
                          "slave": "lower"}),
         (SPHERE, "nts", {}),
         (BLOCKS, "mortar", {"element": "hex1", "n_lower": 4, "n_upper": 2, "slave": "upper"}),
         (BLOCKS, "mortar-dual", {"element": "tet1/hex1", "n_lower": 4, "n_upper": 2,
                                  "slave": "lower"})]
IDS = [f"{n.split('3d')[0]}-{m}" + (f"-{p['element']}-{p['slave']}" if p else "")
       for n, m, p in CASES]


@pytest.fixture(autouse=True)
def _scenes(monkeypatch):
    real = runner.get_scene
    monkeypatch.setattr(runner, "get_scene", lambda name: SCENES.get(name) or real(name))


def _run(case, out, resume=False):
    name, method, params = case
    return runner.run_scene(name, params, method, steps=3, out=out, resume=resume)


def _moments(log: list[tuple[str, int]], seed: int) -> list[int]:
    """Three rename numbers (1-based): in the checkpoint write, in the frames, anywhere."""
    rng = np.random.default_rng(seed)
    ckpt, frames = checkpoint_moments(log), frame_moments(log)
    return [int(rng.choice(ckpt)), int(rng.choice(frames)), int(rng.integers(1, len(log) + 1))]


@pytest.mark.parametrize("case", CASES, ids=IDS)
def test_a_3d_contact_run_killed_anywhere_resumes_to_the_same_frames_and_metrics(
        case, tmp_path):
    seed = zlib.crc32("-".join(IDS[CASES.index(case)]).encode())
    assert_resumes(lambda out, resume=False: _run(case, out, resume), tmp_path,
                   lambda log: _moments(log, seed))


def _frames(out: Path) -> dict:
    return {p.name: read_series(p) for p in sorted(out.glob("*.pvd"))}


def test_the_resumed_3d_run_is_bit_for_bit(tmp_path):
    """Killed after the first step's checkpoint and resumed: every frame's point
    and cell arrays, ``contact.csv`` and the metrics equal the uninterrupted run's
    exactly (RTOL 0), so the 1e-10 above is not what lets the resume pass."""
    from resume_tools import Killed, renames
    case = CASES[1]
    with renames() as log:
        ref = _run(case, tmp_path / "ref")
    kill = checkpoint_moments(log)[1]         # inside the first step's checkpoint
    try:
        with renames(kill_at=kill):
            _run(case, tmp_path / "killed")
    except Killed:
        pass
    got = _run(case, tmp_path / "killed", resume=True)
    assert got["metrics"] == ref["metrics"]
    assert [s["residual_norms"] for s in got["steps"]] == \
        [s["residual_norms"] for s in ref["steps"]]
    a, b = _frames(tmp_path / "ref"), _frames(tmp_path / "killed")
    assert a.keys() == b.keys() and len(a) == 2       # the block and the slave surface
    for name in a:
        assert [t for t, _ in a[name]] == [t for t, _ in b[name]]
        for (_, ma), (_, mb) in zip(a[name], b[name]):
            for kind in ("point_data", "cell_data"):
                da, db = getattr(ma, kind), getattr(mb, kind)
                assert da.keys() == db.keys()
                for k in da:
                    assert all(np.array_equal(x, y, equal_nan=True)
                               for x, y in zip(np.atleast_1d(da[k]), np.atleast_1d(db[k]))), \
                        f"{name} {k}"
    assert (tmp_path / "ref" / "contact.csv").read_bytes() == \
        (tmp_path / "killed" / "contact.csv").read_bytes()
