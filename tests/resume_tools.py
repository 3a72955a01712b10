"""Shared by the resume tests: a simulated kill at a chosen file rename, and the
comparison of two runs' outputs (frames, contact.csv, summary) to 1e-10 relative.

Tolerance: a resumed run repeats the uninterrupted run's solves from the same
checkpointed state, controller, item states and the model's tangent state
(which items' triplets vary, so every tangent is summed in the same order):
measured with SuperLU, every scene and method resumes identical to the last
bit (these tests pass with RTOL = 0).  PARDISO reuses its analysis across
solves, so a resumed run (a fresh analysis) differs at round-off: hertz
mortar-dual's pressure_oscillation, 0 against 1.7e-16 of p0.  1e-10 is the
bound the issue sets; it still fails on any
state, step or item state that was not restored (those move results by far
more than 1e-8).
"""
from __future__ import annotations

import json
import os
import shutil
from contextlib import contextmanager
from pathlib import Path
from typing import Callable, Iterator

import numpy as np

from skfem_mortar.output.io import read_series

RTOL = 1e-10
#: metrics that are relative measures of round-off size (errors of exact answers,
#: penetration over a radius): compared to 1e-10 of 1, the quantity they measure
ROUND_OFF_SUFFIXES = ("_error", "_variation", "_roughness", "penetration", "_oscillation")


class Killed(BaseException):
    """The simulated kill: not an Exception, so nothing on the way catches it."""


@contextmanager
def renames(kill_at: int | None = None) -> Iterator[list[tuple[str, int]]]:
    """Log the atomic renames (every output file is written through one) as
    ``(target, bytes)`` and, at the ``kill_at``-th, leave a truncated temporary
    file behind, as a kill during the write does, and raise :class:`Killed`
    before the rename."""
    real = os.replace
    log: list[tuple[str, int]] = []

    def replace(src, dst):
        log.append((str(dst), Path(src).stat().st_size))
        if len(log) == kill_at:
            data = Path(src).read_bytes()
            Path(src).with_name(Path(src).name + "-killed").write_bytes(data[:len(data) // 2])
            raise Killed(str(dst))
        return real(src, dst)

    os.replace = replace
    try:
        yield log
    finally:
        os.replace = real


def copy_run(src: Path, dst: Path) -> Path:
    shutil.copytree(src, dst)
    return dst


def edit_step(path: Path, edit: Callable[[dict, dict], None]) -> None:
    """Rewrite the checkpoint step file ``path`` after ``edit(arrays, header)``
    changed its arrays (``z``, ``item_<i>``) or its header in place."""
    with np.load(path) as data:
        arrays = {k: data[k] for k in data.files}
    header = json.loads(str(arrays["header"]))
    edit(arrays, header)
    arrays["header"] = np.array(json.dumps(header))
    with open(path, "wb") as f:
        np.savez(f, **arrays)


def _close(a: np.ndarray, b: np.ndarray, scale: float, what: str) -> None:
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    assert a.shape == b.shape, f"{what}: shapes {a.shape} != {b.shape}"
    same_nan = np.isnan(a) == np.isnan(b)
    assert same_nan.all(), f"{what}: undefined at other places"
    ok = np.isnan(a) | (np.abs(a - b) <= RTOL * scale)
    assert ok.all(), (f"{what}: differs by {np.nanmax(np.abs(a - b)):.3e} "
                      f"(scale {scale:.3e})")


def _unit(field: str) -> str:
    """Fields compared on one scale: the stress components and the von Mises
    stress share the stress scale (a component that is exactly zero, like
    sigma_xy of a uniaxial block, is round-off of that scale)."""
    return "stress" if field.startswith("sigma_") or field == "von_mises" else field


def _series(frames: list, kind: str) -> dict[str, np.ndarray]:
    """Per field: its values over all frames, as one array."""
    def flat(v):
        return np.concatenate(v) if kind == "cell_data" else v
    return {k: np.array([flat(getattr(m, kind)[k]) for _, m in frames])
            for k in getattr(frames[0][1], kind)}


def assert_same_frames(ref: Path, out: Path) -> None:
    """Every series: the same frame times, every point and cell field within
    1e-10 of its unit's largest value over the series; contact.csv alike."""
    names = sorted(p.name for p in ref.glob("*.pvd"))
    assert names and names == sorted(p.name for p in out.glob("*.pvd"))
    for name in names:
        fa, fb = read_series(ref / name), read_series(out / name)
        assert [t for t, _ in fa] == [t for t, _ in fb], f"{name}: frame times"
        for kind in ("point_data", "cell_data"):
            a, b = _series(fa, kind), _series(fb, kind)
            assert set(a) == set(b), f"{name}: fields"
            scale: dict[str, float] = {}
            for key, v in a.items():
                scale[_unit(key)] = max(scale.get(_unit(key), 1e-300), np.abs(v).max())
            for key in a:
                _close(a[key], b[key], scale[_unit(key)], f"{name} {key}")
    if (ref / "contact.csv").exists():
        a, b = (np.genfromtxt(d / "contact.csv", delimiter=",", skip_header=1)
                for d in (ref, out))
        _close(a, b, max(np.nanmax(np.abs(a)), 1e-300), "contact.csv")


def assert_same_summary(ref: dict, got: dict) -> None:
    """The same summary but for wall times: identity and counts exactly, load
    factors and increments exactly (the controller replays them), residual norms
    within 1e-10 of the step's first one, metrics within 1e-10 relative."""
    for key in ("scene", "method", "parameters", "n_dofs", "n_multipliers", "converged"):
        assert got[key] == ref[key], key
    assert len(got["steps"]) == len(ref["steps"])
    for k, (a, b) in enumerate(zip(ref["steps"], got["steps"])):
        a, b = dict(a), dict(b)
        norms_a, norms_b = a.pop("residual_norms"), b.pop("residual_norms")
        assert a == b, f"step {k + 1}: {a} != {b}"
        _close(norms_a, norms_b, norms_a[0], f"step {k + 1} residual norms")
    assert set(got["metrics"]) == set(ref["metrics"])
    for key, v in ref["metrics"].items():
        w = got["metrics"][key]
        if isinstance(v, list):
            _close(v, w, max(np.abs(v).max(), 1e-300), f"metric {key}")
        elif isinstance(v, float):
            floor = 1.0 if key.endswith(ROUND_OFF_SUFFIXES) else 0.0
            _close(v, w, max(abs(v), floor), f"metric {key}")
        else:
            assert w == v, f"metric {key}: {w!r} != {v!r}"


def assert_resumes(run: Callable[..., dict], root: Path,
                   moments: Callable[[list[tuple[str, int]]], list[int]]) -> None:
    """``run(out)`` uninterrupted into ``root/ref``; then for each rename number
    ``moments(log)`` picks from its renames (1-based), a run killed there and
    resumed with ``run(out, resume=True)`` gives the same frames and summary."""
    with renames() as log:
        ref = run(root / "ref")
    for n in dict.fromkeys(moments(log)):  # a moment drawn twice is run once
        out = root / f"killed_at_{n}"
        try:
            with renames(kill_at=n):
                run(out)
        except Killed:
            pass
        else:
            raise AssertionError(f"the run was not killed at rename {n}")
        got = run(out, resume=True)
        assert_same_frames(root / "ref", out)
        assert_same_summary(ref, got)


def checkpoint_moments(log: list[tuple[str, int]]) -> list[int]:
    """The rename numbers (1-based) of the checkpoint writes."""
    return [i + 1 for i, (p, _) in enumerate(log) if "/checkpoint/" in p]


def frame_moments(log: list[tuple[str, int]]) -> list[int]:
    """The rename numbers (1-based) of the frame outputs."""
    return [i + 1 for i, (p, _) in enumerate(log) if p.endswith((".vtu", ".pvd"))]
