"""Observers of a solve: output, checkpoints and progress as plugins.

:func:`skfem_mortar.solver.stepping.solve` computes; it writes nothing.  Whatever is
done with the states as they come (a result series, a checkpoint, a progress
bar, a picture) is an :class:`Observer` in ``solve(..., observers=[...])``::

    on_start(model, z, load_factor)   the start state, before the first step
    on_step(record, z)                 after each converged step
    on_end(result)                     when solve returns or raises
                                       (``result.converged`` tells which)

The same observers write a finished :class:`~skfem_mortar.solver.stepping.Result`
(:func:`replay`, used by ``Result.save``) and serve the command-line runner
(:mod:`skfem_mortar.app.runner`, which adds the resume bookkeeping of its output
directory).  The output layer reads items only through the output protocol
(:class:`~skfem_mortar.core.item.Output`, :class:`~skfem_mortar.core.item.ContactTable`).
"""
from __future__ import annotations

import os
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Callable, Iterable, Sequence

import numpy as np

from ..core.item import ContactTable

if TYPE_CHECKING:  # pragma: no cover
    from ..core.item import Output
    from ..core.model import Model
# Result and StepRecord (solver.stepping) are names in annotations only: stepping
# imports this module, never the other way

__all__ = ["Observer", "Callback", "ProgressBar", "SeriesObserver", "CheckpointObserver",
           "ContactCsv", "replay"]


class Observer:
    """Base class of the observers of a solve: every hook does nothing."""

    def on_start(self, model: "Model", z: np.ndarray, load_factor: float) -> None:
        """The start state ``z`` at ``load_factor`` (0, or a restart's), once the
        preflight has passed."""

    def on_step(self, record: "StepRecord", z: np.ndarray) -> None:
        """A converged step: its record (``record.controller`` the step-size
        controller after it) and its unknowns.  ``z`` is the solver's own
        array: copy what you keep."""

    def on_end(self, result: "Result") -> None:
        """The solve ends: ``result.converged`` True when it reached load factor 1,
        False when it raised (the exception follows)."""


class Callback(Observer):
    """``solve(callback=f)``: ``f(record, z)`` after each converged step."""

    def __init__(self, fn: Callable[["StepRecord", np.ndarray], None]):
        self.fn = fn

    def on_step(self, record: "StepRecord", z: np.ndarray) -> None:
        self.fn(record, z)


def in_notebook() -> bool:
    """Whether this process is a Jupyter kernel that shows widgets: IPython's
    ZMQ shell (or a subclass, e.g. Colab's), but not under Qt Console or Spyder
    (the tests of ``tqdm.autonotebook``); IPython is not imported for it."""
    ipython = sys.modules.get("IPython")
    get = getattr(ipython, "get_ipython", None)
    shell = get() if callable(get) else None
    if not any(c.__name__ == "ZMQInteractiveShell" for c in type(shell).__mro__):
        return False
    return not any(k == "QT_API" or k.startswith("SPYDER") for k in os.environ)


def progress_class() -> type:
    """The tqdm class of :class:`ProgressBar`: the notebook widget
    (``tqdm.notebook.tqdm``) in a Jupyter kernel where ipywidgets is installed,
    the text bar (``tqdm.std.tqdm``, on stderr) everywhere else.

    Chosen here rather than by ``tqdm.auto``, which warns in a notebook without
    ipywidgets ("IProgress not found"): neither form warns.
    """
    from importlib.util import find_spec

    if in_notebook() and find_spec("ipywidgets") is not None:
        from tqdm.notebook import tqdm
    else:
        from tqdm.std import tqdm
    return tqdm


class ProgressBar(Observer):
    """A tqdm progress bar of the load steps (``solve(progress=True)``): a widget
    in Jupyter with ipywidgets, else text on stderr (:func:`progress_class`)."""

    def __init__(self):
        self.bar = None

    def on_start(self, model, z, load_factor) -> None:
        tqdm = progress_class()  # imported lazily: the command line starts fast
        self.bar = tqdm(desc="load steps", unit="step", leave=False)

    def on_step(self, record, z) -> None:
        if self.bar is not None:
            self.bar.update(1)
            self.bar.set_postfix_str(
                f"lf={record.load_factor:.3g} it={record.newton_iterations} "
                f"active={record.n_active} r={record.residual_norms[-1]:.1e}")

    def on_end(self, result) -> None:
        if self.bar is not None:
            self.bar.close()
            self.bar = None


class SeriesObserver(Observer):
    """One PVD/VTU series per output (:class:`~skfem_mortar.output.io.SeriesWriter`),
    one frame per state.

    Parameters
    ----------
    out : path
        Output directory.
    outputs : sequence of Output
        What to write (default at :meth:`on_start`: the model's
        :meth:`~skfem_mortar.core.model.Model.outputs`).
    """

    def __init__(self, out: str | os.PathLike, outputs: Sequence["Output"] | None = None):
        self.out = Path(out)
        self.outputs = None if outputs is None else list(outputs)
        self.writers: list | None = None

    def open(self, model: "Model | None" = None) -> None:
        """Make the directory and one writer per output (nothing else is written)."""
        from ..output.io import SeriesWriter

        if self.outputs is None:
            self.outputs = model.outputs()
        self.out.mkdir(parents=True, exist_ok=True)
        self.writers = [SeriesWriter(self.out, o.name, o.output_mesh()) for o in self.outputs]

    def resume(self, load_factors: Sequence[float], states: Sequence[np.ndarray]) -> None:
        """Continue the series of an interrupted run: keep the frames already
        written for ``load_factors`` (the first states of the run), write those
        that are missing."""
        for o, writer in zip(self.outputs, self.writers):
            kept = writer.adopt(load_factors) if len(states) > 1 else 0
            for lf, z in zip(load_factors[kept:], states[kept:]):
                writer.write(lf, *o.output_data(z))

    def frame(self, load_factor: float, z: np.ndarray) -> None:
        """One frame of every series."""
        for o, writer in zip(self.outputs, self.writers):
            pdata, cdata = o.output_data(z)
            writer.write(load_factor, pdata, cdata)

    def on_start(self, model, z, load_factor) -> None:
        if self.writers is None:  # not opened (and resumed) by its owner
            self.open(model)
            self.frame(load_factor, z)

    def on_step(self, record, z) -> None:
        self.frame(record.load_factor, z)


class CheckpointObserver(Observer):
    """A checkpoint step file per converged step (:mod:`skfem_mortar.output.checkpoint`): the
    state, the step record, the step-size controller and the items' states.

    A step's file is written before the index that lists it, so a kill
    leaves a valid checkpoint.

    Parameters
    ----------
    directory : path
        The checkpoint directory.
    meta : dict
        The run's identity (scene, method, parameters, steps).
    items : dict
        ``{name: item}`` whose ``state_dict()`` go into each step
        (:func:`~skfem_mortar.solver.states.stateful_items`; default at
        :meth:`on_start`: the model's).
    run : str
        The run's id ("" for a fresh one, drawn at :meth:`start`).
    first : int
        Number of the next step to write (a resumed run: the steps it has).
    """

    def __init__(self, directory: str | os.PathLike, meta: dict,
                 items: dict | None = None, run: str = "", first: int = 0):
        self.directory = Path(directory)
        self.meta = meta
        self.items = items
        self.run = run
        self.k = first
        self.bytes_written: list[int] = []  # per checkpoint write
        self._pruned = False

    @property
    def legacy(self) -> Path:
        """The single-file checkpoint of older versions, beside the directory."""
        return self.directory.parent / "checkpoint.npz"

    def start(self, z: np.ndarray) -> None:
        """A fresh checkpoint: the old one goes, a new run id, step 0 (``z``)."""
        from ..output.checkpoint import clear_checkpoint

        clear_checkpoint(self.directory)
        self.legacy.unlink(missing_ok=True)
        self.run = os.urandom(16).hex()  # a random id as uuid4().hex, without importing uuid
        self.k = 0
        self.write(z)

    def write(self, z: np.ndarray, record: "StepRecord | None" = None) -> None:
        """Step ``self.k`` (then the next): the first write of a resumed run also
        drops the step files its index does not list."""
        from ..output.checkpoint import prune_checkpoint, write_checkpoint

        k = self.k
        items = {name: it.state_dict() for name, it in self.items.items()} if k else None
        ctl = record.controller.as_dict() if record is not None else None
        self.bytes_written.append(write_checkpoint(
            self.directory, self.meta, self.run, k, z,
            record.as_dict() if record is not None else None, ctl, items))
        if not self._pruned:
            prune_checkpoint(self.directory, k)
            self._pruned = True
        self.k += 1

    def on_start(self, model, z, load_factor) -> None:
        if self.items is None:
            from .states import stateful_items

            self.items = stateful_items(model)
        if not self.run:
            self.start(z)

    def on_step(self, record, z) -> None:
        self.write(z, record)


class ContactCsv(Observer):
    """``contact.csv`` of the last state of the result (the last converged one
    when the solve failed), :func:`~skfem_mortar.output.io.write_contact_csv`.

    ``contact``: ``callable(z) -> dict`` (a pair's ``contact_data``) or a
    :class:`~skfem_mortar.core.item.ContactTable`; default at :meth:`on_start`: the
    model's first contact pair (none: nothing is written).
    """

    def __init__(self, path: str | os.PathLike,
                 contact: "Callable[[np.ndarray], dict] | ContactTable | None" = None):
        self.path = Path(path)
        self.contact = contact.contact_data if isinstance(contact, ContactTable) else contact

    def on_start(self, model, z, load_factor) -> None:
        if self.contact is None:
            tables = model.contact_tables()
            self.contact = tables[0].contact_data if tables else None

    def write(self, z: np.ndarray) -> None:
        from ..output.io import write_contact_csv

        if self.contact is not None:
            # the coordinate columns follow the data: r,z / x,y,z / x,y
            write_contact_csv(self.path, self.contact(z))

    def on_end(self, result) -> None:
        self.write(result.z)


def replay(result: "Result", observers: Iterable[Observer]) -> None:
    """Feed a finished result to ``observers`` as a solve would have: its first
    state, one ``on_step`` per step that has its state, ``on_end``."""
    observers = list(observers)
    states = result.states
    steps = result.steps[len(result.steps) - (len(states) - 1):] if len(states) > 1 else []
    k0 = len(result.steps) - len(steps)
    lf0 = float(result.load_factors[k0])
    for o in observers:
        o.on_start(result.model, states[0], lf0)
    for rec, z in zip(steps, states[1:]):
        for o in observers:
            o.on_step(rec, z)
    for o in observers:
        o.on_end(result)
