"""bench: per-phase timings and the fitted slopes."""
import json

import numpy as np
import pytest

from skfem_mortar.app.bench import PHASES, fit_slopes, run_bench


def test_fit_slopes_recovers_power_laws():
    n = np.array([1e3, 1e4, 1e5])
    rows = [{"status": "ok", "n_dofs": k,
             "time_per_iteration_s": {"bulk": 1e-6 * k, "search": 1e-7 * k,
                                      "contact_assembly": 1e-5 * k**0.5,
                                      "solve": 1e-9 * k**1.5, "output": 0.0}}
            for k in n]
    slopes = fit_slopes(rows + [{"status": "failed: x"}])
    assert slopes["bulk"] == pytest.approx(1.0)
    assert slopes["contact_assembly"] == pytest.approx(0.5)
    assert slopes["solve"] == pytest.approx(1.5)
    assert "output" not in slopes  # zero times have no slope
    # the contact work (search + assembly) 1e-7 k + 1e-5 k^0.5 against the
    # number of contact nodes m = k^0.5: slope between 1 and 2
    rows_m = [dict(r, n_multipliers=r["n_dofs"] ** 0.5) for r in rows]
    assert fit_slopes(rows_m, "n_multipliers")["search"] == pytest.approx(2.0)
    assert 1.0 < fit_slopes(rows_m, "n_multipliers")["contact"] < 2.0


@pytest.mark.slow
def test_quick_bench_writes_json_and_plot(tmp_path):
    report = run_bench(tmp_path, scenes=("seed",), quick=True)
    data = json.loads((tmp_path / "bench.json").read_text())
    assert data == json.loads(json.dumps(report))
    rows = data["scenes"]["seed"]["rows"]
    assert [r["status"] for r in rows] == ["ok", "ok"]
    assert rows[1]["n_dofs"] > rows[0]["n_dofs"]
    for r in rows:
        assert set(r["time_per_iteration_s"]) == set(PHASES)
        assert r["peak_rss_mb"] > 10 and 0 <= r["contact_share"] <= 1
    assert "contact" in data["scenes"]["seed"]["slopes_vs_contact_nodes"]
    assert (tmp_path / "bench.png").stat().st_size > 1000
