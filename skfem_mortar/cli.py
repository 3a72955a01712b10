"""The ``skfem-mortar`` command line (see docs/architecture.md, "command-line contract").

Exit codes: 0 success, 1 a run that did not converge, 2 bad input (unknown
scene, unknown parameter, value out of range).
"""
from __future__ import annotations

import argparse
import json
import logging
import sys
from typing import Sequence

__all__ = ["main"]


def _parse_sets(pairs: Sequence[str]) -> dict[str, str]:
    out: dict[str, str] = {}
    for pair in pairs:
        if "=" not in pair:
            raise ValueError(f"--set takes NAME=VALUE, got {pair!r}")
        key, val = pair.split("=", 1)
        out[key.strip()] = val.strip()
    return out


def _cmd_scenes(args: argparse.Namespace) -> int:
    from .scenes import list_scenes

    scenes = list_scenes()
    if args.json:
        print(json.dumps([{"name": s.name, "summary": s.summary,
                           "methods": [m for m in s.methods if m is not None],
                           "default_steps": s.default_steps,
                           "parameters": {p.name: {"default": p.default, "doc": p.doc,
                                                   "allowed": p.range_text()}
                                          for p in s.params}} for s in scenes]))
        return 0
    for s in scenes:
        methods = ", ".join(m for m in s.methods if m is not None) or "-"
        print(f"{s.name}: {s.summary}  [methods: {methods}; default steps: {s.default_steps}]")
        for p in s.params:
            print(f"    {p.name} = {p.default!r}   {p.doc} ({p.range_text()})")
    return 0


def _cmd_run(args: argparse.Namespace) -> int:
    from .runner import run_scene

    summary = run_scene(args.scene, _parse_sets(args.set), method=args.method,
                        steps=args.steps, out=args.out, progress=not args.no_progress,
                        resume=args.resume)
    if args.json:
        print(json.dumps(summary))
    else:
        print(f"scene {summary['scene']} ({summary['method'] or 'no contact'}): "
              f"{summary['n_dofs']} dofs, {summary['n_multipliers']} multipliers, "
              f"{len(summary['steps'])} steps, {summary['wall_time_s']:.2f} s")
        for k, v in summary["metrics"].items():
            print(f"  {k} = {v}")
        if args.out:
            print(f"results written to {args.out}")
    return 0


def _cmd_demo(args: argparse.Namespace) -> int:
    from .demo import run_demo

    summary = run_demo(args.out, method=args.method, progress=True)
    m = summary["metrics"]
    print(f"seed ({summary['method']}): {len(summary['steps'])} load steps in "
          f"{summary['wall_time_s']:.1f} s; contact force {m['contact_force']:.4g}, "
          f"contact length {m['contact_length']:.4g}, indentation {m['max_indentation']:.4g}")
    print(f"written to {args.out}/: figure.png, pressure.png, newton.png, summary.json, "
          f"contact.csv, cushion.pvd, cable.pvd")
    return 0


def _cmd_study(args: argparse.Namespace) -> int:
    from .study import run_study

    steps = [int(v) for v in args.steps.split(",")] if args.steps else None
    if steps and min(steps) < 1:
        raise ValueError("--steps values must be integers >= 1")
    rows = run_study(args.scene, args.out, methods=args.method or None,
                     sets=_parse_sets(args.set), steps=steps, quick=args.quick,
                     tolerance=args.tolerance, resume=args.resume, workers=args.workers,
                     scheduler=args.scheduler, progress=not args.no_progress)
    failed = sum(r.get("status") != "ok" for r in rows)
    print(f"{len(rows)} runs ({failed} failed): {args.out}/results.csv, pareto.png, report.md")
    return 0


def _cmd_bench(args: argparse.Namespace) -> int:
    from .bench import run_bench

    report = run_bench(args.out, scenes=args.scene or ("hertz", "seed"), method=args.method,
                       quick=args.quick, max_dofs=args.max_dofs, steps=args.steps,
                       progress=not args.no_progress)
    for scene, data in report["scenes"].items():
        for r in data["rows"]:
            if r.get("status") != "ok":
                print(f"{scene} {r['params']}: {r['status']}")
                continue
            t = r["time_per_iteration_s"]
            print(f"{scene} {r['n_dofs']:>8d} dofs: " + ", ".join(
                f"{k} {v * 1e3:.2f} ms" for k, v in t.items()) +
                f"; contact share {100 * r['contact_share']:.1f} %, "
                f"peak {r['peak_rss_mb']:.0f} MB")
        fmt = lambda d: ", ".join(f"{k} {v:.2f}" for k, v in d.items())  # noqa: E731
        print(f"{scene} slopes vs dofs: {fmt(data['slopes'])}")
        print(f"{scene} slopes vs contact nodes: {fmt(data['slopes_vs_contact_nodes'])}")
    print(f"written to {args.out}/bench.json, bench.png")
    return 0


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="skfem-mortar",
        description="Large-deformation frictionless contact (NTS and mortar) on scikit-fem.")
    parser.add_argument("-v", "--verbose", action="store_true", help="log solver details")
    sub = parser.add_subparsers(dest="command", required=True)

    p = sub.add_parser("scenes", help="list scenes, their parameters and defaults")
    p.add_argument("--json", action="store_true")
    p.set_defaults(func=_cmd_scenes)

    p = sub.add_parser("run", help="run a scene")
    p.add_argument("scene")
    p.add_argument("--method", choices=["nts", "mortar", "mortar-dual"], default=None)
    p.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                   help="override a scene parameter (repeatable)")
    p.add_argument("--steps", type=int, default=None, help="number of load steps")
    p.add_argument("--out", default=None, help="output directory")
    p.add_argument("--json", action="store_true", help="print one JSON object on stdout")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.add_argument("--resume", action="store_true",
                   help="continue from the checkpoint in --out (same scene and settings)")
    p.set_defaults(func=_cmd_run)

    p = sub.add_parser("study", help="speed-accuracy grid: error against wall time")
    p.add_argument("--scene", action="append", required=True, help="scene (repeatable)")
    p.add_argument("--method", action="append", choices=["nts", "mortar", "mortar-dual"],
                   help="methods to compare (repeatable; default: all of the scene's)")
    p.add_argument("--set", action="append", default=[], metavar="NAME=V1,V2,...",
                   help="an axis of the grid: a scene parameter and its values")
    p.add_argument("--steps", default=None, help="load step counts to compare, e.g. 5,10,20")
    p.add_argument("--quick", action="store_true", help="a small grid (for CI)")
    p.add_argument("--tolerance", type=float, default=1e-2,
                   help="report the cheapest setting within this relative error")
    p.add_argument("--out", default="skfem-mortar-study")
    p.add_argument("--resume", action="store_true", help="skip rows already in results.csv")
    p.add_argument("--workers", type=int, default=0,
                   help="run on a Dask LocalCluster with this many worker processes")
    p.add_argument("--scheduler", default=None, help="address of an existing Dask scheduler")
    p.add_argument("--no-progress", action="store_true")
    p.set_defaults(func=_cmd_study)

    p = sub.add_parser("bench", help="per-phase timings and peak memory at growing sizes")
    p.add_argument("--scene", action="append", choices=["hertz", "seed"])
    p.add_argument("--method", choices=["nts", "mortar", "mortar-dual"], default="mortar")
    p.add_argument("--quick", action="store_true", help="small sizes only (for CI)")
    p.add_argument("--max-dofs", type=int, default=None, help="stop a scene after this size")
    p.add_argument("--steps", type=int, default=None, help="load steps per run")
    p.add_argument("--out", default="skfem-mortar-bench")
    p.add_argument("--no-progress", action="store_true")
    p.set_defaults(func=_cmd_bench)

    p = sub.add_parser("demo", help="run the demo scene and write its outputs")
    p.add_argument("--out", default="skfem-mortar-demo")
    p.add_argument("--method", choices=["nts", "mortar", "mortar-dual"], default="mortar")
    p.set_defaults(func=_cmd_demo)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.INFO if args.verbose else logging.WARNING,
                        stream=sys.stderr, format="%(levelname)s %(name)s: %(message)s")
    if getattr(args, "steps", None) is not None and args.steps < 1:
        print("skfem-mortar: error: --steps must be an integer >= 1", file=sys.stderr)
        return 2
    from .errors import ConvergenceError

    try:
        return args.func(args)
    except ValueError as exc:
        print(f"skfem-mortar: error: {exc}", file=sys.stderr)
        return 2
    except OSError as exc:
        print(f"skfem-mortar: failed: {exc}", file=sys.stderr)
        return 1
    except ConvergenceError as exc:
        print(f"skfem-mortar: failed: {exc}", file=sys.stderr)
        return 1


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
