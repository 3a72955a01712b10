"""Run Kratos' ``hertz_simple`` ALM frictionless contact test on a given mesh and
write what the side-by-side benchmark needs as JSON (run with the Kratos venv).

    /work/kratos-venv/bin/python benchmarks/kratos/run_kratos.py MESH.mdpa OUT.json [--steps 2]

The parameters are the test's own ``data/hertz_simple_test_parameters.json``
with three changes (everything else, solver, tolerances, contact process, as
the test has it):

* the mesh and materials file names point at the given mesh and at
  ``data/hertz_simple_test_materials.json``;
* the load is ramped, ``NEGATIVE_FACE_PRESSURE = 0.2 t`` with ``time_step =
  1.001 / steps`` (``end_time = 1.0``: ``steps`` steps, the last at
  ``t = 1.001``), so the final load is the pressure 0.2002 on the flat face of
  width 16, the line load ``P = 3.2032`` (the test itself applies 0.2 at once
  in one step of 1.01; the two-step ramp is the variant in Kratos' Hertz
  tutorial, which is what the issue timed);
* the reference-result checks (``json_check_process``) are dropped: their
  reference holds the one-step answer on the 1x mesh only;
* for Kratos 10.4: the processes' ``mesh_id`` (no longer accepted) is dropped
  and the sub-model-part names of the processes and materials are prefixed by
  the root ``Structure.``; the linear solver ``SkylineLUFactorizationSolver``
  is named ``skyline_lu_factorization``.

Written per run: the number of nodes, the Newton iterations per step
(``NL_ITERATION_NUMBER`` after each step), and for every node of the contact
interface its reference coordinates, displacement, the ``SLAVE``/``ACTIVE``
flags, the augmented normal contact pressure (``AUGMENTED_NORMAL_CONTACT_PRESSURE``,
non-historical, negative in compression), the multiplier
``LAGRANGE_MULTIPLIER_CONTACT_PRESSURE`` and ``SCALE_FACTOR``, and the total
plate reaction.  Nothing is post-processed here (see ``side_by_side.py``).
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
import KratosMultiphysics.LinearSolversApplication  # noqa: E402,F401  (sparse_lu etc.)
from KratosMultiphysics.StructuralMechanicsApplication.structural_mechanics_analysis import (  # noqa: E402
    StructuralMechanicsAnalysis)

T_IMPORT = time.perf_counter() - T0
HERE = os.path.dirname(os.path.abspath(__file__))
DATA = os.path.join(HERE, "data")
#: the final pseudo time of the tutorial's two-step ramp (pressure 0.2 t)
T_END = 1.001


def parameters(mesh: str, steps: int, materials_file: str,
               linear_solver: str | None = None) -> KM.Parameters:
    """The test's parameters with the mesh, the ramped load and no result checks
    (``linear_solver``: another Kratos linear solver type instead of the test's)."""
    if steps < 1:
        raise ValueError(f"steps must be >= 1, got {steps}")
    with open(os.path.join(DATA, "hertz_simple_test_parameters.json")) as f:
        p = json.load(f)
    s = p["solver_settings"]
    s["model_import_settings"]["input_filename"] = os.path.splitext(os.path.abspath(mesh))[0]
    s["material_import_settings"]["materials_filename"] = materials_file
    s["time_stepping"]["time_step"] = T_END / steps
    # the same solver under its Kratos 10.4 name
    assert s["linear_solver_settings"]["solver_type"] == "SkylineLUFactorizationSolver"
    s["linear_solver_settings"]["solver_type"] = "skyline_lu_factorization"
    if linear_solver:
        s["linear_solver_settings"]["solver_type"] = linear_solver
    p["processes"]["loads_process_list"][0]["Parameters"]["value"] = "0.2*t"
    p["processes"].pop("json_check_process")
    for group in p["processes"].values():
        for proc in group:
            proc["Parameters"].pop("mesh_id", None)  # a key Kratos 10.4 no longer accepts
            name = proc["Parameters"]["model_part_name"]
            if not name.startswith("Structure"):
                proc["Parameters"]["model_part_name"] = "Structure." + name
    return KM.Parameters(json.dumps(p))


def materials(path: str) -> None:
    """The test's materials with the sub-model-part names under the root
    ``Structure`` (as Kratos 10.4 reads them), written to ``path``."""
    with open(os.path.join(DATA, "hertz_simple_test_materials.json")) as f:
        m = json.load(f)
    for prop in m["properties"]:
        prop["model_part_name"] = "Structure." + prop["model_part_name"]
    with open(path, "w") as f:
        json.dump(m, f)


class Analysis(StructuralMechanicsAnalysis):
    """The structural analysis, recording the Newton iterations of every step."""

    def __init__(self, model, params):
        super().__init__(model, params)
        self.iterations: list[int] = []
        self.times: list[float] = []

    def FinalizeSolutionStep(self):
        info = self._GetSolver().GetComputingModelPart().ProcessInfo
        self.iterations.append(int(info[KM.NL_ITERATION_NUMBER]))
        self.times.append(float(info[KM.TIME]))
        super().FinalizeSolutionStep()


def collect(model: KM.Model, analysis: Analysis) -> dict:
    root = model["Structure"]
    contact = root.GetSubModelPart("Contact_Part")
    info = analysis._GetSolver().GetComputingModelPart().ProcessInfo
    nodes = []
    for n in contact.Nodes:
        d = n.GetSolutionStepValue(KM.DISPLACEMENT)
        nodes.append({
            "id": n.Id, "X": n.X0, "Y": n.Y0, "ux": d[0], "uy": d[1],
            "slave": bool(n.Is(KM.SLAVE)), "active": bool(n.Is(KM.ACTIVE)),
            "augmented_pressure": n.GetValue(CSMA.AUGMENTED_NORMAL_CONTACT_PRESSURE),
            "multiplier": n.GetSolutionStepValue(CSMA.LAGRANGE_MULTIPLIER_CONTACT_PRESSURE),
        })
    plate = root.GetSubModelPart("Parts_parts_plate")
    ry = sum(n.GetSolutionStepValue(KM.REACTION_Y) for n in plate.Nodes)
    scale = info[KM.SCALE_FACTOR] if info.Has(KM.SCALE_FACTOR) else None
    return {"n_nodes": root.NumberOfNodes(), "n_elements": root.NumberOfElements(),
            "iterations": analysis.iterations, "times": analysis.times,
            "scale_factor": scale, "plate_reaction_y": ry, "contact_nodes": nodes}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("mesh", help="the .mdpa mesh (made by make_meshes.py)")
    ap.add_argument("out", help="JSON file to write")
    ap.add_argument("--steps", type=int, default=2, help="load steps (default 2)")
    ap.add_argument("--linear-solver", default=None,
                    help="a Kratos linear solver type instead of the test's skyline LU, "
                         "e.g. sparse_lu (Eigen, LinearSolversApplication)")
    a = ap.parse_args(argv)
    KM.Logger.GetDefaultOutput().SetSeverity(KM.Logger.Severity.WARNING)
    t1 = time.perf_counter()
    model = KM.Model()
    mat = os.path.splitext(os.path.abspath(a.out))[0] + "_materials.json"
    materials(mat)
    analysis = Analysis(model, parameters(a.mesh, a.steps, mat, a.linear_solver))
    analysis.Run()
    t_run = time.perf_counter() - t1
    out = collect(model, analysis)
    out.update({"kratos_version": KM.KratosGlobals.Kernel.Version() if hasattr(
        KM.KratosGlobals, "Kernel") else None, "time_import": T_IMPORT, "time_run": t_run,
        "steps_requested": a.steps,
        "linear_solver": a.linear_solver or "skyline_lu_factorization"})
    with open(a.out, "w") as f:
        json.dump(out, f)
    return 0


if __name__ == "__main__":
    sys.exit(main())
