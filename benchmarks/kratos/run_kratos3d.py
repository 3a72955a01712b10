"""Run one of Kratos' 3D frictionless ALM contact patch tests (``data3d/``) and
write its contact nodes' results as JSON (run with the Kratos venv).

    /work/kratos-venv/bin/python benchmarks/kratos/run_kratos3d.py DECK OUT.json

``DECK`` is a key of :data:`DECKS` (``patch_matching``, ``patch_nonmatching``,
``simplest_triquad``, ``simplest_quadtri``).  The parameters are the test's own
``data3d/<test>_parameters.json`` with these changes only (solver, tolerances,
load, contact process as the test has them):

* the mesh and materials file names point into ``data3d/``;
* the reference-result checks (``json_check_process``) are dropped (the
  comparison is ``decks3d.py``'s);
* for Kratos 10.4: the processes' ``mesh_id`` (no longer accepted) is dropped.

Written: the Kratos version, the Newton iterations of the step, the analysis
time (model import to the end of ``Run``; the imports of Kratos are timed apart
as ``time_import``), and for every node of the contact sub-model part its
reference coordinates, displacement, ``SLAVE``/``ACTIVE`` flags, the augmented
normal contact pressure (``AUGMENTED_NORMAL_CONTACT_PRESSURE``, non-historical,
negative in compression), the multiplier ``LAGRANGE_MULTIPLIER_CONTACT_PRESSURE``
and the process info's ``SCALE_FACTOR``.
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import time

T0 = time.perf_counter()

import KratosMultiphysics as KM  # noqa: E402
import KratosMultiphysics.ContactStructuralMechanicsApplication as CSMA  # noqa: E402
from KratosMultiphysics.StructuralMechanicsApplication.structural_mechanics_analysis import (  # noqa: E402
    StructuralMechanicsAnalysis)

T_IMPORT = time.perf_counter() - T0
HERE = os.path.dirname(os.path.abspath(__file__))
DATA = os.path.join(HERE, "data3d")

#: deck -> (parameters file stem, mesh stem, materials file, contact sub-model part)
DECKS = {
    "patch_matching": ("3D_contact_patch_matching_test", "3D_contact_patch_matching_test",
                       "3D_contact_patch_matching_test_materials.json", "Contact_Part"),
    "patch_nonmatching": ("3D_contact_patch_nonmatching_test",
                          "3D_contact_patch_nonmatching_test",
                          "3D_contact_patch_nonmatching_test_materials.json", "Contact_Part"),
    "simplest_triquad": ("3D_contact_simplest_patch_matching_triquad_test",
                         "3D_contact_simplest_patch_matching_triquad_test",
                         "3D_contact_simplest_patch_matching_test_materials.json",
                         "DISPLACEMENT_Displacement_Auto3"),
    "simplest_quadtri": ("3D_contact_simplest_patch_matching_quadtri_test",
                         "3D_contact_simplest_patch_matching_triquad_test",
                         "3D_contact_simplest_patch_matching_test_materials.json",
                         "DISPLACEMENT_Displacement_Auto3"),
}


def parameters(deck: str) -> KM.Parameters:
    """The test's parameters of ``deck`` with the changes of the module docstring."""
    if deck not in DECKS:
        raise ValueError(f"deck must be one of {sorted(DECKS)}, got {deck!r}")
    stem, mesh, mat, _ = DECKS[deck]
    with open(os.path.join(DATA, stem + "_parameters.json")) as f:
        p = json.load(f)
    s = p["solver_settings"]
    s["model_import_settings"]["input_filename"] = os.path.join(DATA, mesh)
    s["material_import_settings"]["materials_filename"] = os.path.join(DATA, mat)
    p["processes"].pop("json_check_process", None)
    for group in p["processes"].values():
        for proc in group:
            proc["Parameters"].pop("mesh_id", None)  # a key Kratos 10.4 no longer accepts
    return KM.Parameters(json.dumps(p))


class Analysis(StructuralMechanicsAnalysis):
    """The structural analysis, recording the Newton iterations of every step."""

    def __init__(self, model, params):
        super().__init__(model, params)
        self.iterations: list[int] = []

    def FinalizeSolutionStep(self):
        info = self._GetSolver().GetComputingModelPart().ProcessInfo
        self.iterations.append(int(info[KM.NL_ITERATION_NUMBER]))
        super().FinalizeSolutionStep()


def collect(model: KM.Model, analysis: Analysis, contact_part: str) -> dict:
    root = model["Structure"]
    contact = root.GetSubModelPart(contact_part)
    info = analysis._GetSolver().GetComputingModelPart().ProcessInfo
    nodes = []
    for n in contact.Nodes:
        d = n.GetSolutionStepValue(KM.DISPLACEMENT)
        nodes.append({
            "id": n.Id, "X": n.X0, "Y": n.Y0, "Z": n.Z0, "u": [d[0], d[1], d[2]],
            "slave": bool(n.Is(KM.SLAVE)), "active": bool(n.Is(KM.ACTIVE)),
            "augmented_pressure": n.GetValue(CSMA.AUGMENTED_NORMAL_CONTACT_PRESSURE),
            "multiplier": n.GetSolutionStepValue(CSMA.LAGRANGE_MULTIPLIER_CONTACT_PRESSURE),
        })
    scale = info[KM.SCALE_FACTOR] if info.Has(KM.SCALE_FACTOR) else None
    return {"n_nodes": root.NumberOfNodes(), "n_elements": root.NumberOfElements(),
            "iterations": analysis.iterations, "scale_factor": scale,
            "contact_nodes": nodes}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("deck", choices=sorted(DECKS))
    ap.add_argument("out", help="JSON file to write")
    a = ap.parse_args(argv)
    KM.Logger.GetDefaultOutput().SetSeverity(KM.Logger.Severity.WARNING)
    t1 = time.perf_counter()
    model = KM.Model()
    analysis = Analysis(model, parameters(a.deck))
    analysis.Run()
    t_run = time.perf_counter() - t1
    out = collect(model, analysis, DECKS[a.deck][3])
    out.update({"deck": a.deck, "kratos_version": getattr(KM, "__version__", None),
                "time_import": T_IMPORT, "time_run": t_run})
    with open(a.out, "w") as f:
        json.dump(out, f)
    return 0


if __name__ == "__main__":
    sys.exit(main())
