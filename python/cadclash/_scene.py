"""Prepared scenes, one-off collision queries and trajectory replay."""
from __future__ import annotations

import os
from typing import Any, Iterable, List, Optional, Sequence, Tuple, Union

import numpy as np

from . import _cadclash as _core
from ._model import Instance, Model, _path_under
from ._options import CollideOptions, _resolve, _to_core
from ._types import (Counters, InputError, ModelMemory, PairResult, Replay, Report, StepResult, Timeline, Timings,
                     _diagnostics)

__all__ = ["Scene", "collide", "replay"]

InstanceKey = Union[int, str, Instance]
# A rigid 4x4 matrix (anything NumPy reads as 4x4), or (translation, quaternion (qw, qx, qy, qz)).
PoseLike = Union[np.ndarray, Sequence[Sequence[float]], Tuple[Sequence[float], Sequence[float]]]


def _report(model: Model, raw, settings=None) -> Report:
    """The Report of one query; with the report's ``settings`` it also holds its JSON document."""
    raw_pairs, counters, timings, diags, complete, stopped_by, unexamined, memory_charged, model_bytes, record = raw
    paths, part_names, surface_names, step_ids = model._names()
    pairs = []
    for ia, ib, sa, sb, contact, intersecting, distance, penetration, exact, tri, by, lo, hi, within in raw_pairs:
        whole = sa < 0  # containment: whole instances
        pairs.append(PairResult(
            contact=contact, instance_a=paths[ia], instance_b=paths[ib], part_a=part_names[ia],
            part_b=part_names[ib], surface_a=None if whole else surface_names[sa],
            surface_b=None if whole else surface_names[sb], step_id_a=None if whole else step_ids[sa],
            step_id_b=None if whole else step_ids[sb], intersecting=intersecting, distance=distance,
            penetration=penetration, exact_distance=exact, instance_id_a=ia, instance_id_b=ib,
            surface_id_a=None if whole else sa, surface_id_b=None if whole else sb, triangle_pairs=tri,
            decided_by=by, distance_lo=lo, distance_hi=hi, contact_within=within))
    run_diagnostics = _diagnostics(diags)
    document = None
    if settings is not None:  # as `cadclash check --json` assembles it
        document = _core.ReportDocument(
            list(model.files), settings, record, [str(d) for d in model.diagnostics + run_diagnostics],
            model.complete and complete and not any(d.is_error for d in run_diagnostics))
    return Report(pairs, Counters(**counters), Timings(**timings), run_diagnostics, complete, stopped_by,
                  [(paths[a], paths[b]) for a, b in unexamined], memory_charged, ModelMemory(**model_bytes), document)


def _given(model: Model, keys) -> List[str]:
    """select_a / select_b as the report's settings show them: path prefixes as given, ids and
    Instances as their paths."""
    if keys is None:
        return []
    if isinstance(keys, (str, int, Instance)):
        keys = [keys]
    return [k if isinstance(k, str) else model.instances[model._instance_id(k)].path for k in keys]


def _select(model: Model, keys: Optional[Iterable], what: str) -> List[int]:
    """Instance ids for select_a / select_b: ids, Instances, or path prefixes (every instance at or
    below the path)."""
    if keys is None:
        return []
    if isinstance(keys, (str, int, Instance)):
        keys = [keys]
    ids: List[int] = []
    for k in keys:
        if isinstance(k, str):
            found = [i.id for i in model.instances if _path_under(i.path, k)]
            if not found:
                raise ValueError(f"{what}: no instance path at or under {k!r}")
            ids.extend(found)
        else:
            ids.append(model._instance_id(k))
    return sorted(set(ids))


def _pose(transform) -> np.ndarray:
    if isinstance(transform, (tuple, list)) and len(transform) == 2:
        return _core.pose_from_translation_quaternion(transform[0], transform[1])
    return _core.pose_from_matrix(transform)


class Scene:
    """A prepared scene over a model: per-surface BVHs and instance boxes are built once (on first
    use), and each ``check()`` updates only the instances moved since the last one.

    ``select_a`` / ``select_b``: instance ids, ``Instance`` objects or path prefixes (a path selects
    every instance at or below it); a pair is checked when one side is in A and the other in B
    (empty: every instance). ``exclude``: sub-assembly paths whose inner pairs are skipped (the CLI's
    --exclude-under). ``exclude_pairs``: (path, path) pairs never checked. A prefix matching no
    instance is a ValueError.

    The scene starts from the model's imported poses and keeps its own poses: ``set_transform`` never
    changes ``model.instances[i].pose``. The scene keeps its model alive. Every call is thread-safe;
    calls on scenes of one model serialise on the model's lock, taken with the GIL released.
    """

    def __init__(self, model: Model, select_a=None, select_b=None, exclude: Optional[Iterable[str]] = None,
                 exclude_pairs: Optional[Iterable[Tuple[str, str]]] = None):
        if not isinstance(model, Model):
            raise TypeError("Scene needs a cadclash.Model (from cadclash.load)")
        if isinstance(exclude, str):
            exclude = [exclude]
        self.model = model
        self._given = (_given(model, select_a), _given(model, select_b), list(exclude or []))
        self._core = _core.SceneCore(model, _select(model, select_a, "select_a"), _select(model, select_b, "select_b"),
                                     [tuple(p) for p in (exclude_pairs or [])], list(exclude or []))

    def set_transform(self, instance: InstanceKey, transform: PoseLike) -> None:
        """Moves an instance (id, path or Instance) to an absolute part-local → world pose: a rigid 4x4
        matrix (array-like), or ``(translation, quaternion)`` with (tx, ty, tz) in mm and (qw, qx, qy,
        qz) normalised here. ValueError for a matrix that is not a rotation + translation; KeyError /
        IndexError for an unknown instance."""
        self._core.set_pose(self.model._instance_id(instance), _pose(transform))

    def transform(self, instance: InstanceKey) -> np.ndarray:
        """The instance's current pose in this scene (a new 4x4 array)."""
        return self._core.pose(self.model._instance_id(instance))

    def reset_transform(self, instance: InstanceKey) -> None:
        """Puts an instance back at its imported pose."""
        iid = self.model._instance_id(instance)
        self._core.set_pose(iid, self.model.instances[iid].pose)

    @property
    def running(self) -> bool:
        """True while ``check()`` or ``replay()`` of this scene runs in some thread."""
        return self._core.running

    def check(self, options: Optional[CollideOptions] = None, **kwargs: Any) -> Report:
        """Reports penetrating, touching, clearance and containment pairs at the current poses.
        Options as a ``CollideOptions`` and/or keyword arguments (see ``CollideOptions``). The query
        runs with the GIL released, so other Python threads keep running; the result does not depend
        on the thread count. Lazy surfaces a query reaches are tessellated in the model."""
        o = _to_core(_resolve(options, kwargs))
        settings = _core.report_settings(o, self.model, *self._given)
        return _report(self.model, self._core.check(o), settings)

    def __repr__(self) -> str:
        return f"Scene({self.model!r})"


def collide(model: Model, a: InstanceKey, b: InstanceKey, options: Optional[CollideOptions] = None,
            **kwargs: Any) -> Report:
    """One-off query of two different instances (ids, paths or Instances) at their imported poses;
    tessellates exactly the lazy surfaces it needs. Runs with the GIL released. ValueError if a == b."""
    o = _to_core(_resolve(options, kwargs))
    settings = _core.report_settings(o, model, [], [], [])
    return _report(model, _core.collide(model, model._instance_id(a), model._instance_id(b), o), settings)


def replay(scene: Scene, trajectory: Union[str, os.PathLike], options: Optional[CollideOptions] = None, *,
           continuous: bool = False, time_resolution: float = 1e-3, motion_checks: int = 4096,
           **kwargs: Any) -> Replay:
    """Replays a trajectory CSV (``step,instance_path,tx,ty,tz,qw,qx,qy,qz``; absolute world poses;
    optional header; '#' comments) on ``scene``: rows with equal consecutive step numbers are
    applied together, then the scene is checked. The scene keeps the last poses afterwards.

    ``continuous=True`` checks the motion between the steps too, as ``cadclash check --path
    --continuous``: ``Replay.timeline`` lists every instance pair that may be in contact between
    the first and last step, with spans in step numbers; ``time_resolution`` (a fraction of the
    stretch between two steps) and ``motion_checks`` (static checks at most per stretch) as there.
    Step numbers must then ascend (a step that goes back is an error in ``Replay.diagnostics`` and
    the path stops there).

    Raises ``InputError`` naming the file and line when the file cannot be read or any row is bad
    (then nothing is run, like ``cadclash check --path``). Rows naming unknown instances are skipped
    with a warning in ``Replay.diagnostics``. Runs with the GIL released."""
    path = os.fspath(trajectory)
    o = _to_core(_resolve(options, kwargs))
    try:
        with open(path, "rb") as f:
            text = f.read()
    except OSError as e:
        raise InputError(f"{path}: error: cannot open trajectory ({e.strerror})", []) from e
    parse_raw, steps_raw, run_raw, distinct_steps, timeline = scene._core.replay(
        text, path, o, continuous, float(time_resolution), int(motion_checks))
    parse = _diagnostics(parse_raw)
    if any(d.is_error for d in parse):
        raise InputError(f"{path}: the trajectory has errors; nothing checked", parse)
    steps = [StepResult(step, _report(scene.model, raw)) for step, raw in steps_raw]
    replay_diagnostics = _diagnostics(run_raw)
    document = _replay_document(scene, o, path, steps, steps_raw, distinct_steps, replay_diagnostics, timeline)
    return Replay(steps, parse + replay_diagnostics, document, Timeline._from_raw(document._timeline()))


def _replay_document(scene: Scene, o, path: str, steps, steps_raw, distinct_steps: int, replay_diagnostics,
                     timeline=None):
    """The `cadclash check --path` report of a replay, assembled as the CLI does."""
    model = scene.model
    not_checked = distinct_steps - len(steps)
    stopped_by = next((s.report.stopped_by for s in steps if not s.report.complete), "")
    path_error = any(d.is_error for d in replay_diagnostics)  # continuous: a step that goes back
    if not stopped_by and not_checked > 0 and not path_error:
        stopped_by = "time budget"
    step_diagnostics = [d for s in steps for d in s.report.diagnostics]
    diagnostics = [str(d) for d in replay_diagnostics + model.diagnostics + step_diagnostics]
    complete = model.complete and not any(d.is_error for d in step_diagnostics) and not stopped_by and not path_error
    settings = _core.report_settings(o, model, *scene._given)
    return _core.ReportDocument.trajectory(list(model.files), settings, path,
                                           [(step, raw[9]) for step, raw in steps_raw], not_checked, stopped_by,
                                           diagnostics, complete, timeline)
