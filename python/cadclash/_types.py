"""Plain result values: diagnostics, surface-pair results, counters, reports.

Every value here is a snapshot: it holds no reference to the model or scene that produced it and
stays valid after they are gone.
"""
from __future__ import annotations

import datetime
import json
import os
from dataclasses import dataclass, field, make_dataclass, replace
from typing import Iterator, List, Optional, Tuple, Union

import numpy as np

from . import _cadclash as _core

__all__ = ["Diagnostic", "InputError", "Provenance", "PairResult", "Counters", "Timings", "Report",
           "StepResult", "Replay"]


@dataclass(frozen=True)
class Diagnostic:
    """One problem found in untrusted input (a CAD/mesh file, a trajectory), and where.

    ``str(d)`` is the C++ ``format_diagnostic`` text: ``"file:line: error: message"`` or
    ``"file: #id: error: message"``.
    """

    severity: str            # "error" or "warning"
    file: str                # the path as given; "" when none
    line: int                # 1-based line in ``file``; 0 when the format has no lines
    step_id: Optional[int]   # STEP entity #id the message is about; None when none
    message: str             # one sentence
    text: str = field(repr=False, default="")  # the formatted line

    @property
    def is_error(self) -> bool:
        return self.severity == "error"

    def __str__(self) -> str:
        return self.text

    @classmethod
    def _from_text(cls, text: str) -> "Diagnostic":
        """The inverse of ``format_diagnostic``: "file[:line]: [#id: ]error|warning: message"."""
        for severity in ("error", "warning"):
            head, sep, message = text.partition(f": {severity}: ")
            if sep:
                break
        else:
            return cls("error", "", 0, None, text, text)
        step_id = None
        if ": #" in head:
            head, _, sid = head.rpartition(": #")
            step_id = int(sid) if sid.isdigit() else None
        file, line = head, 0
        stem, colon, number = head.rpartition(":")
        if colon and number.isdigit():
            file, line = stem, int(number)
        return cls(severity, "" if file == "<input>" else file, line, step_id, message, text)

    @classmethod
    def _from_raw(cls, raw) -> "Diagnostic":
        severity, file, line, step_id, message, text = raw
        return cls(severity, file, int(line), None if step_id < 0 else int(step_id), message, text)


def _diagnostics(raw_list) -> List[Diagnostic]:
    return [Diagnostic._from_raw(r) for r in raw_list]


class InputError(Exception):
    """Bad input that leaves nothing to work with: no file could be read into any instance (or
    ``load(strict=True)`` met an error), or a trajectory has a bad row.

    ``str(e)`` lists every error diagnostic, each naming the file and line or the STEP ``#id``;
    ``e.diagnostics`` holds all of them (warnings too).
    """

    def __init__(self, summary: str, diagnostics: List[Diagnostic]):
        lines = [str(d) for d in diagnostics if d.is_error] or [str(d) for d in diagnostics]
        super().__init__("\n".join([summary] + lines))
        self.diagnostics = diagnostics


@dataclass(frozen=True)
class Provenance:
    """Where a surface came from (C++ ``cadclash::Provenance``)."""

    kind: str                     # "step-face", "iges-face", "brep-face", "obj-group", "off-colour-group", "mesh", "segment"
    source_file: str
    step_id: Optional[int]        # STEP #id of the ADVANCED_FACE (IGES: directory entry); None if unknown
    face_index: int               # index of the face / group / colour within its part, as read
    source_name: str              # the file's own name for it; may be ""
    parent: Optional[int]         # kind == "segment": the surface id this patch was cut from
    colour: Optional[Tuple[float, float, float]]  # RGB in [0, 1] as the file writes it
    healed: bool                  # OCCT shape fixing changed the face before tessellation
    repaired: bool                # mesh repair changed the triangles


@dataclass(frozen=True)
class PairResult:
    """One reported surface pair (or, for ``contact == "containment"``, one instance pair).

    ``instance_a`` is the instance with the smaller id. Surfaces are named by the model's surface
    name and, for STEP faces, the ``#id`` of the ADVANCED_FACE. For containment the surface fields
    are None (the whole part). ``distance`` is the minimum triangle distance, 0 when intersecting
    (containment: ``math.inf`` when beyond the search margin); ``penetration`` is the crossing-depth
    estimate (a lower bound in early-exit mode). See ``contact_classes.h`` for the exact class definitions.
    """

    contact: str                  # "penetrating", "touching", "clearance", "containment" or "undecided"
    instance_a: str               # instance paths
    instance_b: str
    part_a: str
    part_b: str
    surface_a: Optional[str]
    surface_b: Optional[str]
    step_id_a: Optional[int]
    step_id_b: Optional[int]
    intersecting: bool
    distance: float
    penetration: float
    exact_distance: Optional[float]   # BRepExtrema's distance when the decision asked for it (an upper bound)
    instance_id_a: Optional[int]   # None in a report read by Report.from_json
    instance_id_b: Optional[int]
    surface_id_a: Optional[int]
    surface_id_b: Optional[int]
    # all_triangles=True only: intersecting (triangle of A, triangle of B) index pairs, k x 2 uint32 (a copy).
    triangle_pairs: np.ndarray = field(repr=False, compare=False)
    # What settled the class ("mesh", "mesh-exact", "analytic", "refined", "exact", "undecided") and
    # the bounds [distance_lo, distance_hi] on the exact faces' distance it established (collide.h).
    decided_by: str = "mesh"
    distance_lo: float = 0.0
    distance_hi: float = 0.0
    # Penetrating and touching pairs: "tolerance" when the tolerance alone holds the contact, "model
    # uncertainty" when only the faces' ε does; None when the interval cannot tell (contact_classes.h, ContactWithin).
    contact_within: Optional[str] = None

    @property
    def key(self) -> tuple:
        """(instance_a, instance_b, step_id_a or surface_a, step_id_b or surface_b, contact): what
        identifies the pair across runs and against the CLI's JSON report."""
        side_a = self.step_id_a if self.step_id_a is not None else self.surface_a
        side_b = self.step_id_b if self.step_id_b is not None else self.surface_b
        return (self.instance_a, self.instance_b, side_a, side_b, self.contact)


# The field lists and enum names are the C++ library's (cadclash/report.h), so the bindings, the
# CLI and the JSON report cannot disagree on them.
Counters = make_dataclass("Counters", [(name, int, 0) for name in _core.COUNTER_FIELDS], frozen=True)
Counters.__module__ = __name__
Counters.__doc__ = ("Work counters of one query (the paper's Table 2); independent of the thread count. The fields "
                    "are the JSON report's `counters` (docs/report-schema.md).")

Timings = make_dataclass("Timings", [(name, float, 0.0) for name in _core.TIMING_FIELDS], frozen=True)
Timings.__module__ = __name__
Timings.__doc__ = "Seconds spent per stage of one query. Never deterministic; leave out of comparisons."

@dataclass(frozen=True)
class ModelMemory:
    """What the scene's collision model held after a query, in bytes per component (the JSON
    report's ``model``, ``Scene::memory()`` in C++): the triangles and vertices of the surfaces that
    have a hierarchy, the hierarchies built so far and the per-instance data; ``triangle_count`` is
    the triangles counted. The same for any thread count. Zeros in a report written before it."""

    triangles: int = 0
    vertices: int = 0
    hierarchies: int = 0
    instances: int = 0
    triangle_count: int = 0

    @property
    def total(self) -> int:
        return self.triangles + self.vertices + self.hierarchies + self.instances

    @property
    def bytes_per_triangle(self) -> float:
        """total / triangle_count (0.0 when no triangle is held)."""
        return self.total / self.triangle_count if self.triangle_count else 0.0


_CLASSES = _core.CONTACT_CLASSES
_DECIDED_BY = _core.DECIDED_BY


@dataclass(frozen=True)
class Report:
    """The answer of one query: pairs sorted by (instance_a, instance_b, surface_a, surface_b)
    ids, counters, timings, and diagnostics for surfaces that could not be tessellated (skipped).
    Iterating a report iterates its pairs.

    ``complete`` is False when a budget (``time_budget`` / ``memory_budget``) ran out: ``pairs`` then
    holds what was found, ``stopped_by`` says which budget, and ``unexamined_pairs`` lists the
    (path, path) instance pairs not fully examined. ``memory_charged`` is the bytes the query built
    (computed with or without a budget; the same for any thread count)."""

    pairs: List[PairResult]
    counters: Counters
    timings: Timings = field(compare=False)
    diagnostics: List[Diagnostic]
    complete: bool = True
    stopped_by: str = ""
    unexamined_pairs: List[Tuple[str, str]] = field(default_factory=list)
    memory_charged: int = 0
    model: ModelMemory = field(default_factory=ModelMemory)
    # The JSON report of this query (files, settings, model diagnostics); None for a Report made by hand.
    _document: Optional["_core.ReportDocument"] = field(default=None, repr=False, compare=False)

    def __iter__(self) -> Iterator[PairResult]:
        return iter(self.pairs)

    def __len__(self) -> int:
        return len(self.pairs)

    def to_json(self, timings: bool = False) -> str:
        """The versioned JSON report (docs/report-schema.md), byte for byte what
        ``cadclash check FILES --json OUT [--no-timings]`` writes for the same files, load and
        query options: ``files`` are the paths given to ``load()``, ``settings`` the load's
        tessellation and this query's options (``select_a``/``select_b``/``exclude`` as given, ids
        and Instances as their paths; ``exclude_pairs`` has no CLI switch and is not shown),
        ``diagnostics`` the model's and then the query's, ``complete`` false when the model is
        incomplete, the query reported an error or a budget ran out. ``timings=False`` is
        ``--no-timings``. ValueError for a Report built by hand or a trajectory step."""
        if self._document is None:
            raise ValueError("this report has no JSON document (only Scene.check(), collide() and "
                             "Report.from_json() reports have one)")
        return self._document.to_json(timings)

    @classmethod
    def from_json(cls, text: str) -> "Report":
        """Reads a report written by ``cadclash check --json`` or ``to_json()``; ``to_json()`` of
        the result gives ``text`` back byte for byte (with ``timings=True`` when it has timings).

        Pairs carry names and STEP ids but no model ids (``instance_id_a`` ... are None) and
        ``diagnostics`` are every diagnostic of the report (the model's and the query's), parsed
        from their text. ValueError, naming the JSON path (e.g. ``/pairs/3/class``), for anything
        that is not a version-2 report of one query (a ``--path`` report holds several: read it
        with ``Replay.from_json``)."""
        doc = _core.ReportDocument.from_json(text)
        return _query_from_document(doc._query(), [Diagnostic._from_text(t) for t in doc.diagnostics],
                                    doc.complete, doc)

    def count(self, contact: str) -> int:
        """Number of pairs of one class ("penetrating", "touching", "clearance", "containment")."""
        if contact not in _CLASSES:
            raise ValueError(f"unknown contact class {contact!r}; one of {', '.join(_CLASSES)}")
        return sum(1 for p in self.pairs if p.contact == contact)

    @property
    def collision(self) -> bool:
        """True when a penetrating, touching, containment or undecided pair was found in a clash
        no approval covers (the CLI's ``--fail-on-collision`` condition: an undecided pair may be a
        contact; see ``review()`` for approvals)."""
        review = self._review()
        if review is None:
            return any(p.contact != "clearance" for p in self.pairs)
        return any(c["status"] != "resolved" and c["approval"] is None and c["class"] != "clearance"
                   for c in review["clashes"])

    def _review(self) -> Optional[dict]:
        if self._document is None:
            return None
        text = self._document._review_json()
        return None if text is None else json.loads(text)

    @property
    def clashes(self) -> List[dict]:
        """The report's ``clashes`` (docs/report-schema.md, "Clash"; docs/review.md): one dict per
        instance pair with its stable ``id``, ``status``, worst ``class``, ``approval`` and
        ``surface_pairs`` (``pair`` indexes ``pairs``). Every clash is "new" until ``review()`` is
        given a baseline. ValueError for a Report built by hand."""
        review = self._review()
        if review is None:
            raise ValueError("this report has no JSON document, hence no clashes")
        return review["clashes"]

    @property
    def review_summary(self) -> dict:
        """The report's ``review`` object: baseline, approvals file, today, group_by, counts per
        status (``summary``) and what became of each approval."""
        review = self._review()
        if review is None:
            raise ValueError("this report has no JSON document, hence no review")
        return review["review"]

    def review(self, baseline: Optional["Report"] = None, approvals: Optional[Union[str, "os.PathLike"]] = None,
               today: Optional[str] = None, group_by: str = "instance", depth_change: float = 0.01,
               baseline_file: str = "") -> "Report":
        """This report with its clashes reviewed as ``cadclash check --baseline --approvals`` does
        (docs/review.md): statuses against ``baseline`` (another Report, e.g. ``Report.from_json``
        of yesterday's file), the approvals file at ``approvals`` applied with expiries judged on
        ``today`` (YYYY-MM-DD; default the UTC date), clashes grouped by ``group_by``. Returns a
        new Report; ``to_json()`` then writes the review. ValueError naming the JSON pointer for a
        bad approvals file."""
        if self._document is None:
            raise ValueError("this report has no JSON document to review")
        if baseline is not None and baseline._document is None:
            raise ValueError("the baseline has no JSON document")
        text, name = None, ""
        if approvals is not None:
            name = os.fspath(approvals)
            with open(name, encoding="utf-8") as f:
                text = f.read()
        if today is None:
            today = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d")
        doc = self._document.reviewed(None if baseline is None else baseline._document, text, name,
                                      baseline_file, today, group_by, depth_change)
        return replace(self, _document=doc)

    def summary(self) -> dict:
        """Counts per class, like the ``summary`` object of the CLI's JSON report."""
        out = {"pairs": len(self.pairs)}
        out.update({c: self.count(c) for c in _CLASSES})
        by = {d: 0 for d in _DECIDED_BY}
        for p in self.pairs:
            if p.contact != "containment":
                by[p.decided_by] += 1
        out["decided_by"] = by
        within = {"unknown": 0, "tolerance": 0, "model uncertainty": 0}
        for p in self.pairs:
            if p.contact in ("penetrating", "touching"):
                within[p.contact_within or "unknown"] += 1
        out["contact_within"] = within
        return out


def _query_from_document(raw, diagnostics: List[Diagnostic], complete: bool, document) -> Report:
    raw_pairs, counters, timings, stopped_by, unexamined, memory_charged, model = raw
    return Report([_pair_from_document(p) for p in raw_pairs], Counters(**counters), Timings(**(timings or {})),
                  diagnostics, complete, stopped_by, [tuple(u) for u in unexamined], memory_charged,
                  ModelMemory(**model), document)


def _pair_from_document(raw) -> PairResult:
    contact, by, lo, hi, intersecting, distance, penetration, exact, tri, a, b, within = raw
    (instance_a, part_a, surface_a, step_a), (instance_b, part_b, surface_b, step_b) = a, b
    return PairResult(
        contact=contact, instance_a=instance_a, instance_b=instance_b, part_a=part_a, part_b=part_b,
        surface_a=surface_a, surface_b=surface_b, step_id_a=step_a, step_id_b=step_b, intersecting=intersecting,
        distance=distance, penetration=penetration, exact_distance=exact, instance_id_a=None, instance_id_b=None,
        surface_id_a=None, surface_id_b=None, triangle_pairs=tri, decided_by=by, distance_lo=lo, distance_hi=hi,
        contact_within=within)


@dataclass(frozen=True)
class StepResult:
    """The report of one trajectory step (rows with equal step numbers are applied together)."""

    step: int
    report: Report


@dataclass(frozen=True)
class TimelineSpan:
    """Where a pair may be in contact along a path, in step numbers (``replay(..., continuous=True)``):
    proved in contact at ``t0`` and at ``t1`` when ``contact_at_ends`` (between them not proved
    either way), else at most the resolution of its stretch wide, where a contact may begin, end or
    hold. A time in no span is proved free."""

    t0: float
    t1: float
    contact_at_ends: bool


@dataclass(frozen=True)
class SurfaceTimeline:
    """One surface pair's spans: each side (instance path, part, surface name, STEP #id or None)."""

    a: Tuple[str, str, Optional[str], Optional[int]]
    b: Tuple[str, str, Optional[str], Optional[int]]
    spans: List[TimelineSpan]


@dataclass(frozen=True)
class ClosestApproach:
    """With a clearance: the pair's minimum distance over the path lies in [lo, hi] (mm) and is
    reached within [t0, t1] (step numbers)."""

    lo: float
    hi: float
    t0: float
    t1: float


@dataclass(frozen=True)
class PairTimeline:
    """One instance pair (paths) that may be in contact somewhere along the path, or (with a
    clearance) comes within it: its spans (any of its surface pairs, or containment), each surface
    pair's, and its closest approach (None without a clearance)."""

    a: str
    b: str
    spans: List[TimelineSpan]
    surfaces: List[SurfaceTimeline]
    closest: Optional[ClosestApproach] = None


@dataclass(frozen=True)
class Timeline:
    """The motion between the steps of a path (``cadclash check --path --continuous``): every instance
    pair not listed is proved out of contact over the whole path. ``resolution``: the width of the
    spans where a contact begins or ends, as a fraction of the stretch between two steps; ``checks``:
    static checks it took; ``complete`` false when a stretch ran out of ``motion_checks``."""

    resolution: float
    checks: int
    complete: bool
    pairs: List[PairTimeline]

    @classmethod
    def _from_raw(cls, raw) -> Optional["Timeline"]:
        if raw is None:
            return None
        resolution, checks, complete, pairs = raw

        def spans(v):
            return [TimelineSpan(t0, t1, c) for t0, t1, c in v]

        return cls(resolution, checks, complete,
                   [PairTimeline(a, b, spans(s), [SurfaceTimeline(tuple(sa), tuple(sb), spans(ss)) for sa, sb, ss in surfaces],
                                 ClosestApproach(*closest) if closest is not None else None)
                    for a, b, s, surfaces, closest in pairs])


@dataclass(frozen=True)
class Replay:
    """Result of ``replay()``: one report per step, and warnings for rows naming unknown instances
    (those rows are skipped) plus any tessellation errors."""

    steps: List[StepResult]
    diagnostics: List[Diagnostic]
    # The `cadclash check --path` JSON report of this replay; None for a Replay made by hand.
    _document: Optional["_core.ReportDocument"] = field(default=None, repr=False, compare=False)
    # With continuous=True: the motion between the steps; None otherwise.
    timeline: Optional[Timeline] = None

    @classmethod
    def from_json(cls, text: str) -> "Replay":
        """Reads a trajectory report written by ``cadclash check --path CSV --json`` or
        ``Replay.to_json()``; ``to_json()`` of the result gives ``text`` back byte for byte (with
        ``timings=True`` when it has timings). Each step's ``Report`` has the step's pairs (names
        and STEP ids, no model ids), counters, timings, ``model`` bytes and budget fields, no
        diagnostics and no JSON document of its own; ``diagnostics`` are the report's, parsed from
        their text. ValueError, naming the JSON path, for anything that is not a version-2
        trajectory report (a report of one query: ``Report.from_json``)."""
        doc = _core.ReportDocument.from_json(text)
        _, raw_steps, _, _ = doc._steps()
        steps = [StepResult(step, _query_from_document(raw, [], not raw[3], None)) for step, raw in raw_steps]
        return cls(steps, [Diagnostic._from_text(t) for t in doc.diagnostics], doc, Timeline._from_raw(doc._timeline()))

    @property
    def steps_not_checked(self) -> int:
        """Steps a time budget left unchecked (0 for a Replay made by hand)."""
        return self._document._steps()[2] if self._document is not None else 0

    def to_json(self, timings: bool = False) -> str:
        """The JSON report of the replay, byte for byte what ``cadclash check FILES --path CSV --json
        OUT [--no-timings]`` writes for the same files, trajectory path (as given) and options (see
        ``Report.to_json``). ValueError for a Replay built by hand."""
        if self._document is None:
            raise ValueError("this replay has no JSON document (only replay() results have one)")
        return self._document.to_json(timings)

    def __iter__(self) -> Iterator[StepResult]:
        return iter(self.steps)

    def __len__(self) -> int:
        return len(self.steps)
