"""Plain result values: diagnostics, surface-pair results, counters, reports.

Every value here is a snapshot: it holds no reference to the model or scene that produced it and
stays valid after they are gone.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Iterator, List, Optional, Tuple

import numpy as np

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
    estimate (a lower bound in early-exit mode). See ``collide.h`` for the exact class definitions.
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
    instance_id_a: int
    instance_id_b: int
    surface_id_a: Optional[int]
    surface_id_b: Optional[int]
    # all_triangles=True only: intersecting (triangle of A, triangle of B) index pairs, k x 2 uint32 (a copy).
    triangle_pairs: np.ndarray = field(repr=False, compare=False)
    # What settled the class ("mesh", "mesh-exact", "analytic", "refined", "exact", "undecided") and
    # the bounds [distance_lo, distance_hi] on the exact faces' distance it established (collide.h).
    decided_by: str = "mesh"
    distance_lo: float = 0.0
    distance_hi: float = 0.0

    @property
    def key(self) -> tuple:
        """(instance_a, instance_b, step_id_a or surface_a, step_id_b or surface_b, contact): what
        identifies the pair across runs and against the CLI's JSON report."""
        side_a = self.step_id_a if self.step_id_a is not None else self.surface_a
        side_b = self.step_id_b if self.step_id_b is not None else self.surface_b
        return (self.instance_a, self.instance_b, side_a, side_b, self.contact)


@dataclass(frozen=True)
class Counters:
    """Work counters of one query (the paper's Table 2); independent of the thread count."""

    instance_pairs: int = 0
    aabb_tests: int = 0
    aabb_updates: int = 0
    surfaces_a: int = 0
    surfaces_b: int = 0
    surface_pairs: int = 0
    triangles_a: int = 0
    triangles_b: int = 0
    triangle_tests: int = 0
    exact_fallbacks: int = 0
    distance_tests: int = 0
    intersecting_pairs: int = 0
    tessellated_surfaces: int = 0
    decided_mesh: int = 0
    decided_mesh_exact: int = 0
    decided_analytic: int = 0
    decided_refined: int = 0
    decided_exact: int = 0
    undecided: int = 0
    ambiguous_pairs: int = 0
    refined_surfaces: int = 0
    exact_queries: int = 0
    witness_queries: int = 0
    dismissed_pairs: int = 0


@dataclass(frozen=True)
class Timings:
    """Seconds spent per stage of one query. Never deterministic; leave out of comparisons."""

    broad: float = 0.0
    surface_level: float = 0.0
    tessellation: float = 0.0
    triangle_level: float = 0.0
    total: float = 0.0


_CLASSES = ("penetrating", "touching", "clearance", "containment", "undecided")
_DECIDED_BY = ("mesh", "mesh-exact", "analytic", "refined", "exact", "undecided")


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

    def __iter__(self) -> Iterator[PairResult]:
        return iter(self.pairs)

    def __len__(self) -> int:
        return len(self.pairs)

    def count(self, contact: str) -> int:
        """Number of pairs of one class ("penetrating", "touching", "clearance", "containment")."""
        if contact not in _CLASSES:
            raise ValueError(f"unknown contact class {contact!r}; one of {', '.join(_CLASSES)}")
        return sum(1 for p in self.pairs if p.contact == contact)

    @property
    def collision(self) -> bool:
        """True when a penetrating, touching, containment or undecided pair was found (the CLI's
        ``--fail-on-collision`` condition: an undecided pair may be a contact)."""
        return any(p.contact != "clearance" for p in self.pairs)

    def summary(self) -> dict:
        """Counts per class, like the ``summary`` object of the CLI's JSON report."""
        out = {"pairs": len(self.pairs)}
        out.update({c: self.count(c) for c in _CLASSES})
        by = {d: 0 for d in _DECIDED_BY}
        for p in self.pairs:
            if p.contact != "containment":
                by[p.decided_by] += 1
        out["decided_by"] = by
        return out


@dataclass(frozen=True)
class StepResult:
    """The report of one trajectory step (rows with equal step numbers are applied together)."""

    step: int
    report: Report


@dataclass(frozen=True)
class Replay:
    """Result of ``replay()``: one report per step, and warnings for rows naming unknown instances
    (those rows are skipped) plus any tessellation errors."""

    steps: List[StepResult]
    diagnostics: List[Diagnostic]

    def __iter__(self) -> Iterator[StepResult]:
        return iter(self.steps)

    def __len__(self) -> int:
        return len(self.steps)
