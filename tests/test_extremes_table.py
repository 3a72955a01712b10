"""benchmarks/extremes_table.py: records of the extremes suite into its table."""
import importlib.util
from pathlib import Path

spec = importlib.util.spec_from_file_location(
    "extremes_table", Path(__file__).resolve().parents[1] / "benchmarks" / "extremes_table.py")
table = importlib.util.module_from_spec(spec)
spec.loader.exec_module(table)


def test_rows_name_the_case_method_outcome_iterations_and_cuts():
    recs = [
        {"test": "tests/test_x.py::test_large_gap[mortar-dual]", "outcome": "passed",
         "iterations": [4, 3], "cuts": 0},
        {"test": "tests/test_x.py::test_ratio[1000.0-mortar]", "outcome": "passed",
         "iterations": [3], "cuts": 2},
        {"test": "tests/test_x.py::test_tiny_nts_fails_clearly", "outcome": "passed",
         "iterations": [4], "cuts": 14},
        {"test": "tests/test_x.py::test_table", "outcome": "failed", "iterations": [],
         "cuts": 0},
    ]
    rows = table.rows_from(recs)
    assert rows[0] == ("large gap", "mortar-dual", "converged, check held",
                       "max 4 over 2 steps", "0")
    assert rows[1] == ("ratio [1000.0]", "mortar", "converged, check held",
                       "max 3 over 1 steps", "2")
    assert rows[2][1:3] == ("nts", "clear failure, as checked") and rows[2][4] == "14"
    assert rows[3][2] == "FAILED" and rows[3][3] == "-"
    md = table.to_markdown(rows)
    assert md.count("\n") == len(rows) + 2 and md.startswith("| case | method |")
