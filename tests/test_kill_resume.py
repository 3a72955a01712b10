"""Killed at any moment, resumed: the same frames and metrics as an uninterrupted
run, for every scene and method (issue #13, item 5).

Each case runs once uninterrupted, counting the atomic renames through which
every output file is written; then three times killed at a seeded random
rename (one inside the checkpoint write: a step file or the index; one inside
the frame output; one anywhere, summary.json included) and resumed.  A kill
between two renames leaves the same files as one at the next rename, so these
moments cover every state the output directory can be left in.  The kill is
simulated in the process (:class:`resume_tools.Killed`, leaving a truncated
temporary file as a real kill does); ``test_resume`` kills real processes.
"""
import zlib

import numpy as np
import pytest
from resume_tools import assert_resumes, checkpoint_moments, frame_moments

from skfem_mortar.app.runner import run_scene

#: every scene and method at a small size, steps enough for step cutting and
#: growth (ironing mortar-dual, seed nts cut steps) and a changing contact zone
CASES = [("block", None, {"refine": 1}, 4),
         ("ring", None, {"n_elements": 8}, 4),
         ("cable_arc", None, {"n_elements": 8}, 4)]
for _m in ("nts", "mortar", "mortar-dual"):
    CASES += [("cable_flat", _m, {"n_elements": 20}, 6),
              ("hertz", _m, {"refine": -3}, 3),
              ("ironing", _m, {"n_block": 6, "n_die": 8, "slide": 1.0}, 8),
              ("patch", _m, {"n_top": 2, "n_bottom": 2}, 3),
              ("seed", _m, {"n_cable": 8, "refine_cushion": 0}, 6)]
# 3-node contact segments (quadratic bodies): curved NTS, curved mortar
CASES += [("hertz", "nts", {"refine": -3, "element": "tri2"}, 3),
          ("hertz", "mortar-dual", {"refine": -3, "element": "quad2"}, 3),
          ("patch", "mortar", {"n_top": 3, "n_bottom": 2, "element": "tri2"}, 3)]


def _run(case, out, resume=False):
    scene, method, params, steps = case
    return run_scene(scene, params, method, steps=steps, out=out, resume=resume)


def _moments(log: list[tuple[str, int]], seed: int) -> list[int]:
    """Three rename numbers (1-based): in the checkpoint write, in the frames, anywhere."""
    rng = np.random.default_rng(seed)
    ckpt, frames = checkpoint_moments(log), frame_moments(log)
    return [int(rng.choice(ckpt)), int(rng.choice(frames)), int(rng.integers(1, len(log) + 1))]


@pytest.mark.parametrize("case", CASES, ids=[f"{c[0]}-{c[1] or 'bulk'}"
                                             + (f"-{c[2]['element']}" if "element" in c[2] else "")
                                             for c in CASES])
def test_killed_anywhere_resumes_to_the_same_frames_and_metrics(case, tmp_path):
    seed = zlib.crc32(f"{case[0]}-{case[1]}".encode())
    assert_resumes(lambda out, resume=False: _run(case, out, resume), tmp_path,
                   lambda log: _moments(log, seed))
