"""The ``skfem-mortar`` command line (see the README, "Command line").

Exit codes:

===  ==========================================================================
0    success
1    a run that did not converge (and nothing else)
2    bad input or a refusal: unknown scene, parameter or option value out of
     range, a busy ``--out`` or one holding another run's files
3    an output could not be written (an OSError: disk full, permission)
4    an internal error (a bug): the traceback is printed
130  interrupted (Ctrl-C): the outputs written so far are kept, the lock released
===  ==========================================================================

Every refusal is one line on stderr naming the option and what it allows.
"""
from __future__ import annotations

import argparse
import json
import logging
import math
import os
import sys
import threading
import traceback
import warnings
from typing import Callable, NoReturn, Sequence

from ..contact import BUILTIN_METHODS, DEFAULT_METHOD
from .interrupt import held_ctrl_c

__all__ = ["main"]


#: exit codes (module docstring)
EXIT_OK, EXIT_NOT_CONVERGED, EXIT_BAD_INPUT, EXIT_WRITE, EXIT_BUG, EXIT_INTERRUPTED = (
    0, 1, 2, 3, 4, 130)


class _Parser(argparse.ArgumentParser):
    """An argument parser whose errors are one line (no usage block) and exit 2."""

    def error(self, message: str) -> NoReturn:
        self.exit(EXIT_BAD_INPUT, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def _parse_sets(pairs: Sequence[str]) -> dict[str, str]:
    """``--set NAME=VALUE`` pairs as a dict; ValueError on a malformed or repeated one."""
    out: dict[str, str] = {}
    for pair in pairs:
        if "=" not in pair:
            raise ValueError(f"--set takes NAME=VALUE, got {pair!r}")
        key, val = (t.strip() for t in pair.split("=", 1))
        if key in out:
            raise ValueError(f"--set {key} given twice ({out[key]!r} and {val!r}); "
                             "give each parameter once")
        out[key] = val
    return out


def _int_at_least(low: int) -> Callable[[str], int]:
    """An argparse type: an integer >= ``low``."""
    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            value = None
        if value is None or value < low:
            raise argparse.ArgumentTypeError(f"must be an integer >= {low}, got {text!r}")
        return value
    return parse


def _steps_list(text: str) -> list[int]:
    """An argparse type: load step counts, integers >= 1 separated by commas."""
    try:
        values = [int(v) for v in text.split(",")]
    except ValueError:
        values = []
    if not values or min(values) < 1:
        raise argparse.ArgumentTypeError(
            f"must be integers >= 1 separated by commas, got {text!r}")
    return values


def _positive_float(text: str) -> float:
    """An argparse type: a finite number > 0."""
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not (math.isfinite(value) and value > 0):
        raise argparse.ArgumentTypeError(f"must be a finite number > 0, got {text!r}")
    return value


def _out_dir(text: str) -> str:
    """An argparse type: a directory name, not empty, not an existing file."""
    from ..output.outdir import check_out_dir

    try:
        check_out_dir(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc).removeprefix("--out ")) from None
    return text


def _check_args(parser: argparse.ArgumentParser, args: argparse.Namespace) -> None:
    """What argparse cannot say alone (before anything heavy is imported)."""
    if args.command == "run":
        if args.resume and args.out is None:
            parser.error("--resume needs --out DIR (the directory of the run to continue)")
        if args.replace and args.out is None:
            parser.error("--replace needs --out DIR (the directory to replace)")
        if args.resume and args.replace:
            parser.error("--resume and --replace exclude each other")
    if hasattr(args, "set"):
        try:
            args.sets = _parse_sets(args.set)
        except ValueError as exc:
            parser.error(str(exc))


def _cmd_scenes(args: argparse.Namespace) -> int:
    from ..scenes import list_scenes

    scenes = list_scenes()
    if args.json:
        print(json.dumps([{"name": s.name, "summary": s.summary,
                           "methods": [m for m in s.methods if m is not None],
                           "default_method": s.check_method(None),
                           "default_steps": s.default_steps,
                           "one_step": s.one_step_text or None,
                           "parameters": {p.name: {"default": p.default, "doc": p.doc,
                                                   "allowed": p.range_text()}
                                          for p in s.params}} for s in scenes]))
        return 0
    for s in scenes:
        default = s.check_method(None)
        methods = ", ".join(m + (" (default)" if m == default else "")
                            for m in s.methods if m is not None) or "-"
        one = f", 1 {s.one_step_text}" if s.one_step_text else ""
        print(f"{s.name}: {s.summary}  [methods: {methods}; default steps: {s.default_steps}{one}]")
        for p in s.params:
            print(f"    {p.name} = {p.default!r}   {p.doc} ({p.range_text()})")
    return 0


def _cmd_run(args: argparse.Namespace) -> int:
    from .runner import run_scene

    summary = run_scene(args.scene, args.sets, method=args.method,
                        steps=args.steps, out=args.out, progress=not args.no_progress,
                        resume=args.resume, replace=args.replace, linear=args.linear)
    if args.json:
        print(json.dumps(summary))
    else:
        print(f"scene {summary['scene']} ({summary['method'] or 'no contact'}): "
              f"{summary['n_dofs']} dofs, {summary['n_multipliers']} multipliers, "
              f"{len(summary['steps'])} steps, {summary['wall_time_s']:.2f} s")
        for k, v in summary["metrics"].items():
            print(f"  {k} = {_number_text(v)}")
        if args.out:
            print(f"results written to {args.out}")
    return 0


def _number_text(v: object) -> str:
    """A value on the console: floats to 12 significant digits (the summary's
    load factors are rounded so already), everything else as it is."""
    return f"{v:.12g}" if isinstance(v, float) else str(v)


def _cmd_demo(args: argparse.Namespace) -> int:
    from .demo import run_demo

    summary = run_demo(args.out, method=args.method, progress=True, replace=args.replace)
    m = summary["metrics"]
    print(f"seed ({summary['method']}): {len(summary['steps'])} load steps in "
          f"{summary['wall_time_s']:.1f} s; contact force {m['contact_force']:.4g}, "
          f"contact length {m['contact_length']:.4g}, indentation {m['max_indentation']:.4g}")
    print(f"written to {args.out}/: figure.png, pressure.png, newton.png, summary.json, "
          f"contact.csv, cushion.pvd, cable.pvd")
    return 0


def _cmd_study(args: argparse.Namespace) -> int:
    from ..output.outdir import output_lock
    from .study import run_study
    from .study_plan import check_repeat, check_tolerances, plan_study

    options = dict(methods=args.method or None, sets=args.sets, steps=args.steps,
                   solvers=args.solver, metric=args.metric, quick=args.quick)
    plan = plan_study(args.scene, **options)  # every refusal before --out is made
    check_repeat(args.repeat, len(plan.runs))
    check_tolerances(args.tolerance)
    with output_lock(args.out, "study"):
        rows = run_study(args.scene, args.out, **options, repeat=args.repeat,
                         tolerance=args.tolerance, resume=args.resume, workers=args.workers,
                         scheduler=args.scheduler, progress=not args.no_progress)
    failed = sum(r.get("status") != "ok" for r in rows)
    print(f"{len(rows)} runs ({failed} failed): {args.out}/results.csv, pareto.png, report.md, "
          "recommendations.csv")
    return 0


def _cmd_bench(args: argparse.Namespace) -> int:
    from .bench import run_bench
    from ..output.outdir import output_lock

    with output_lock(args.out, "bench"):
        report = run_bench(args.out, scenes=args.scene or ("hertz", "seed"),
                           method=args.method, quick=args.quick, max_dofs=args.max_dofs,
                           steps=args.steps, progress=not args.no_progress,
                           solvers=args.solver)
    for scene, data in report["scenes"].items():
        for r in data["rows"]:
            if r.get("status") != "ok":
                print(f"{scene} {r['params']}: {r['status']}")
                continue
            t = r["time_per_iteration_s"]
            print(f"{scene} {r['n_dofs']:>8d} dofs: " + ", ".join(
                f"{k} {v * 1e3:.2f} ms" for k, v in t.items()) +
                f"; contact share {100 * r['contact_share']:.1f} %, "
                f"peak {r['peak_rss_mb']:.0f} MB; {r['newton_iterations']} Newton its, "
                f"{r['factorizations']} factorizations, {r['krylov_iterations']} Krylov its")
        fmt = lambda d: ", ".join(f"{k} {v:.2f}" for k, v in d.items())  # noqa: E731
        print(f"{scene} slopes vs dofs: {fmt(data['slopes'])}")
        print(f"{scene} slopes vs contact nodes: {fmt(data['slopes_vs_contact_nodes'])}")
    print(f"written to {args.out}/bench.json, bench.png")
    return 0


def _scene_names() -> list[str]:
    """The scenes' names, from the modules of :mod:`skfem_mortar.scenes` (none is
    imported: ``--help`` stays as fast as the rest of the command line)."""
    import importlib.util
    import pkgutil

    spec = importlib.util.find_spec("skfem_mortar.scenes")
    paths = list(spec.submodule_search_locations or []) if spec else []
    return sorted(m.name for m in pkgutil.iter_modules(paths) if not m.name.startswith("_"))


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="skfem-mortar",
        description="Large-deformation contact (NTS and mortar, frictionless or with "
                    "Coulomb or Tresca friction) for 2D models on scikit-fem.",
        epilog="exit codes: 0 ok, 1 did not converge, 2 bad input or refusal, 3 an output "
               "could not be written, 4 internal error, 130 interrupted")
    parser.add_argument("-v", "--verbose", action="store_true", help="log solver details")
    sub = parser.add_subparsers(dest="command", required=True)
    steps = _int_at_least(1)
    _add_scenes(sub)
    _add_run(sub, steps)
    _add_study(sub)
    _add_bench(sub, steps)
    _add_demo(sub)
    for sp in sub.choices.values():
        sp.set_defaults(parser=sp)  # its errors name the command
    return parser


def _add_scenes(sub) -> None:
    """The ``scenes`` sub-command and its arguments."""
    p = sub.add_parser("scenes", help="list scenes, their parameters and defaults")
    p.add_argument("--json", action="store_true")
    p.set_defaults(func=_cmd_scenes)


def _add_run(sub, steps: Callable[[str], int]) -> None:
    """The ``run`` sub-command and its arguments (``steps``: the load steps' type)."""
    names = ", ".join(_scene_names())
    p = sub.add_parser("run", help="run a scene",
                       description=f"Run a scene: {names}. `skfem-mortar scenes` lists "
                                   "their parameters, defaults and allowed ranges.")
    p.add_argument("scene", help=f"one of {names}")
    p.add_argument("--method", choices=BUILTIN_METHODS, default=None,
                   help=f"contact method (default: {DEFAULT_METHOD}, for a scene with contact)")
    p.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                   help="override a scene parameter (repeatable, once per parameter)")
    p.add_argument("--steps", type=steps, default=None, help="number of load steps (>= 1)")
    p.add_argument("--out", type=_out_dir, default=None,
                   help="output directory (one run: locked while it runs)")
    p.add_argument("--json", action="store_true", help="print one JSON object on stdout")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.add_argument("--resume", action="store_true",
                   help="continue from the checkpoint in --out (same scene and settings)")
    p.add_argument("--replace", action="store_true",
                   help="remove the files of the run --out holds first")
    p.add_argument("--linear", choices=("direct", "krylov", "auto"), default=None,
                   help="Newton's linear solves: a factorization per iteration (direct, the "
                        "default), or inexact with kept factors (krylov; auto: krylov from "
                        "4e4 unknowns on)")
    p.set_defaults(func=_cmd_run)


def _add_study(sub) -> None:
    """The ``study`` sub-command and its arguments."""
    p = sub.add_parser("study", help="speed-accuracy grid: error against wall time")
    p.add_argument("--scene", action="append", required=True, help="scene (repeatable)")
    p.add_argument("--method", action="append", choices=BUILTIN_METHODS,
                   help="methods to compare (repeatable; default: all of the scene's)")
    p.add_argument("--set", action="append", default=[], metavar="NAME=V1,V2,...",
                   help="an axis of the grid: a scene parameter and its values")
    p.add_argument("--steps", type=_steps_list, default=None,
                   help="load step counts to compare, e.g. 5,10,20 (each >= 1)")
    p.add_argument("--solver", action="append", default=None, metavar="PATH",
                   help="solver paths to compare (repeatable): a backend installed here "
                        "(superlu, pardiso), optionally +krylov or +auto for inexact Newton "
                        "with kept factors, e.g. pardiso+krylov; default: the default "
                        "backend, direct")
    p.add_argument("--metric", action="append", default=None, metavar="NAME",
                   help="the plotted error measure (default: the scene's first; repeatable "
                        "for several scenes: each plots the first it has)")
    p.add_argument("--repeat", type=_int_at_least(1), default=None,
                   help="timed runs per setting, the median reported (>= 1; default 3 "
                        "for a grid of at most 12 points, else 1)")
    p.add_argument("--quick", action="store_true", help="a small grid (for CI)")
    p.add_argument("--tolerance", type=_positive_float, action="append", default=None,
                   help="a relative error to recommend the cheapest setting for (in (0, 1); "
                        "repeatable; default 0.1, 0.03, 0.01, 0.003)")
    p.add_argument("--out", type=_out_dir, default="skfem-mortar-study")
    p.add_argument("--resume", action="store_true", help="skip rows already in results.csv")
    p.add_argument("--workers", type=_int_at_least(0), default=0,
                   help="run on a Dask LocalCluster with this many worker processes (>= 0)")
    p.add_argument("--scheduler", default=None, help="address of an existing Dask scheduler")
    p.add_argument("--no-progress", action="store_true")
    p.set_defaults(func=_cmd_study)


def _add_bench(sub, steps: Callable[[str], int]) -> None:
    """The ``bench`` sub-command and its arguments (``steps``: the load steps' type)."""
    p = sub.add_parser("bench", help="per-phase timings and peak memory at growing sizes")
    p.add_argument("--scene", action="append", choices=["hertz", "seed", "block3d"])
    p.add_argument("--method", choices=BUILTIN_METHODS, default=DEFAULT_METHOD,
                   help=f"contact method (default: {DEFAULT_METHOD})")
    p.add_argument("--quick", action="store_true", help="small sizes only (for CI)")
    p.add_argument("--max-dofs", type=_int_at_least(1), default=None,
                   help="run no size with more displacement dofs than this (>= 1)")
    p.add_argument("--steps", type=steps, default=None, help="load steps per run (>= 1)")
    p.add_argument("--solver", action="append", default=None, metavar="PATH",
                   help="solver paths to time side by side (repeatable, as for study: "
                        "pardiso, pardiso+krylov, superlu, ...; default: the default backend)")
    p.add_argument("--out", type=_out_dir, default="skfem-mortar-bench")
    p.add_argument("--no-progress", action="store_true")
    p.set_defaults(func=_cmd_bench)


def _add_demo(sub) -> None:
    """The ``demo`` sub-command and its arguments."""
    p = sub.add_parser("demo", help="run the demo scene and write its outputs")
    p.add_argument("--out", type=_out_dir, default="skfem-mortar-demo")
    p.add_argument("--method", choices=BUILTIN_METHODS, default=DEFAULT_METHOD,
                   help=f"contact method of the run (default: {DEFAULT_METHOD}); "
                        "pressure.png compares it with NTS (with mortar if it is NTS)")
    p.add_argument("--replace", action="store_true",
                   help="remove the files of an earlier run in --out first")
    p.set_defaults(func=_cmd_demo)


def _one_line_warning(message, category, filename, lineno, line=None) -> str:
    """A warning as one line on the command line (a model's warning, e.g. the
    preflight's, names its cause and fix; the source line would only be runpy's)."""
    return f"skfem-mortar: warning: {message}\n"


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; return the exit code (module docstring).

    A refusal of the arguments themselves (argparse's, and ``--resume`` without
    ``--out``, a repeated ``--set``) raises ``SystemExit(2)`` as argparse does.
    """
    warnings.formatwarning = _one_line_warning
    parser = build_parser()
    args = parser.parse_args(argv)  # a refusal here is SystemExit(2), --help SystemExit(0)
    _check_args(args.parser, args)
    _last["command"] = args.command
    logging.basicConfig(level=logging.INFO if args.verbose else logging.WARNING,
                        stream=sys.stderr, format="%(levelname)s %(name)s: %(message)s")
    try:
        with held_ctrl_c():  # a Ctrl-C dropped where Python cannot raise ends the next step
            return _dispatch(args)
    except KeyboardInterrupt:
        print(f"skfem-mortar: interrupted{_kept(args)}", file=sys.stderr)
        return EXIT_INTERRUPTED


def _kept(args: argparse.Namespace) -> str:
    """What an interrupted command leaves: the outputs so far (a run: resumable)."""
    if getattr(args, "out", None) is None:
        return ""
    again = ", continue with --resume" if args.command in ("run", "study") else ""
    return f"; the outputs written so far to {args.out} are kept{again}"


def _dispatch(args: argparse.Namespace) -> int:
    """The command, its failures mapped to exit codes."""
    from ..core.errors import ConvergenceError

    try:
        return args.func(args)
    except ConvergenceError as exc:
        print(f"skfem-mortar: failed: {exc}", file=sys.stderr)
        return EXIT_NOT_CONVERGED
    except ValueError as exc:
        print(f"skfem-mortar: error: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except OSError as exc:
        print(f"skfem-mortar: could not write the outputs: {exc}", file=sys.stderr)
        return EXIT_WRITE
    except Exception:
        traceback.print_exc()
        print("skfem-mortar: internal error (a bug; please report it with the traceback "
              "above)", file=sys.stderr)
        return EXIT_BUG


#: the command :func:`main` ran last (for :func:`entry`)
_last: dict[str, str] = {}


def entry() -> NoReturn:
    """The ``skfem-mortar`` program: :func:`main`, then the exit.

    After ``run`` everything is written and closed, and the interpreter's own
    teardown (freeing numpy's, scipy's and scikit-fem's module objects: about
    0.1 s, an eighth of a small run's process) does nothing for the user, so the
    process ends at once (``os._exit``) once the streams are flushed and logging
    is shut down, and only when no other thread runs (a normal exit otherwise;
    ``SKFEM_MORTAR_NORMAL_EXIT=1`` forces one).  Other commands exit normally.
    """
    code = main()
    if (_last.get("command") == "run" and not os.environ.get("SKFEM_MORTAR_NORMAL_EXIT")
            and threading.active_count() == 1):
        logging.shutdown()
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(code)
    sys.exit(code)


if __name__ == "__main__":  # pragma: no cover
    entry()
