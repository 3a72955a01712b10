"""Scene ``balloon``: p(lambda) of the inflated hemisphere against
p = 2 mu H / R (1/lambda - 1/lambda^7) under volume control, second order in
the meridian elements; under pressure control the run stops at the limit point."""
import json
import subprocess
import sys

import numpy as np
import pytest

from skfem_mortar.app.runner import run_scene
from skfem_mortar.scenes.balloon import LIMIT_STRETCH, P_MAX_FACTOR, balloon_pressure


@pytest.fixture(scope="module")
def errors():
    out = {}
    for n in (32, 64, 128):
        s = run_scene("balloon", {"n_elements": n})
        assert s["converged"]
        out[n] = s["metrics"]
    return out


def test_closed_form():
    assert P_MAX_FACTOR == pytest.approx(1.2395, abs=5e-5)
    assert balloon_pressure(LIMIT_STRETCH, 1.0, 1.0, 1.0) == pytest.approx(P_MAX_FACTOR,
                                                                           rel=1e-15)


def test_pressure_against_closed_form_at_second_order(errors):
    """40 volumes from lambda = 1.05 to 3 (at least the 20 asked for); the error,
    relative to p_max, below 1e-3 from 64 elements on (about (pi/n)^2 / 8 expected:
    3e-4 at 64; measured 7.5e-5) and falling at order 2 (measured 2.00, 2.00)."""
    e = {n: m["pressure_error"] for n, m in errors.items()}
    assert all(m["compared_volumes"] >= 20 for m in errors.values())
    assert e[64] < 1e-3 and e[128] < 1e-3
    orders = [np.log2(e[32] / e[64]), np.log2(e[64] / e[128])]
    assert all(1.8 < q < 2.2 for q in orders), orders
    m = errors[128]   # the maximum passed: the largest pressure at lambda = 1.4 (a step's)
    assert m["stretch"] == pytest.approx(3.0, rel=1e-9)
    assert m["pressure_max"] == pytest.approx(m["pressure_max_exact"], rel=1e-3)
    assert abs(m["stretch_at_pressure_max"] - LIMIT_STRETCH) < 0.05    # the step 0.05


def test_pressure_control_exits_1_at_the_limit_point(tmp_path):
    proc = subprocess.run([sys.executable, "-m", "skfem_mortar.app.cli", "run", "balloon",
                           "--set", "control=pressure", "--out", str(tmp_path / "b")],
                          capture_output=True, text=True)
    assert proc.returncode == 1
    assert ("pressure control cannot pass it; prescribe the enclosed volume instead"
            in proc.stderr)
    assert "limit point near load factor" in proc.stderr
    summary = json.loads((tmp_path / "b" / "summary.json").read_text())
    steps = summary["steps"]
    p_last = 1.2 * steps[-1]["load_factor"]              # pressure_ratio 1.2 of p_max
    assert 0.98 <= p_last <= 1.0
    assert sum(s["cuts"] for s in steps) <= 2
