"""Collision query options: keyword arguments or a ``CollideOptions`` object, named like the CLI's
``cadclash check`` switches."""
from __future__ import annotations

from dataclasses import dataclass, fields, replace
from typing import Optional

from . import _cadclash as _core

__all__ = ["CollideOptions"]

# Name -> value, from the C++ library's name tables (cadclash/report.h): the CLI's switch values.
_PARALLEL = _core.PARALLEL_VERSIONS
_SCHEDULE = _core.SCHEDULES
_TRIANGLE_LEVEL = _core.TRIANGLE_LEVELS


@dataclass(frozen=True)
class CollideOptions:
    """Options of ``Scene.check``, ``collide`` and ``replay`` (C++ ``cadclash::CollideOptions``).

    Every query also accepts these as keyword arguments; ``check(opts, tolerance=0.5)`` overrides one
    field of ``opts``. An unknown keyword is a TypeError, a bad value a ValueError.
    """

    tolerance: float = 0.0          # contact tolerance, mm (>= 0); touching: distance <= tolerance + both deflections
    clearance: float = 0.0          # also report non-touching pairs closer than this, mm (0 = never)
    all_triangles: bool = False     # visit every candidate triangle pair and list the intersecting ones
    threads: int = 0                # OpenMP threads; <= 0: OpenMP's default. Results do not depend on it
    parallel: str = "v1"            # "v1" (per surface pair) or "v2" (flattened surface pair x triangle block)
    schedule: str = "guided"        # OpenMP schedule: "guided", "dynamic", "static"
    brute_force: bool = False       # every surface pair and triangle pair, no OAABB culling (for comparison)
    triangle_level: str = "auto"    # candidate triangle pairs: "auto", "flat" loops or "bvh"
    flat_limit: int = 4096          # "auto" switches to the BVH above this many candidate pairs
    containment: bool = True        # detect a closed part inside another
    exact: bool = False             # every reported class from the exact B-rep faces (slow); see collide.h
    fast: bool = False              # classes from the triangles' deflection band alone, not certified
    # Budgets; 0 = none. When one runs out the query returns a partial report (Report.complete False,
    # Report.stopped_by says which). time_budget: seconds of wall clock (for replay: the whole replay;
    # which pairs finish then depends on the machine). memory_budget: bytes of what the query builds;
    # the partial report is then the same for any thread count. See collide.h for the exact rules.
    time_budget: float = 0.0
    memory_budget: int = 0


_FIELD_NAMES = frozenset(f.name for f in fields(CollideOptions))


def _resolve(options: Optional[CollideOptions], overrides: dict) -> CollideOptions:
    unknown = set(overrides) - _FIELD_NAMES
    if unknown:
        raise TypeError(f"unknown collision option(s): {', '.join(sorted(unknown))}; "
                        f"known: {', '.join(sorted(_FIELD_NAMES))}")
    if options is None:
        options = CollideOptions()
    elif not isinstance(options, CollideOptions):
        raise TypeError("options must be a cadclash.CollideOptions")
    return replace(options, **overrides) if overrides else options


def _choice(table: dict, name: str, value):
    try:
        return table[value]
    except (KeyError, TypeError):
        raise ValueError(f"{name} must be one of {', '.join(table)}; got {value!r}") from None


def _to_core(o: CollideOptions) -> "_core.CollideOptionsCore":
    c = _core.CollideOptionsCore()
    c.tolerance = float(o.tolerance)
    c.clearance = float(o.clearance)
    c.mode = _core.CollideMode.AllTrianglePairs if o.all_triangles else _core.CollideMode.EarlyExit
    c.threads = int(o.threads)
    c.version = _choice(_PARALLEL, "parallel", o.parallel)
    c.schedule = _choice(_SCHEDULE, "schedule", o.schedule)
    c.use_oaabb = not o.brute_force
    c.triangle_level = _choice(_TRIANGLE_LEVEL, "triangle_level", o.triangle_level)
    if int(o.flat_limit) < 0:
        raise ValueError("flat_limit must be >= 0")
    c.flat_limit = int(o.flat_limit)
    c.detect_containment = bool(o.containment)
    if o.exact and o.fast:
        raise ValueError("exact and fast exclude each other")
    c.decision = (_core.DecisionMode.Exact if o.exact else
                  _core.DecisionMode.Fast if o.fast else _core.DecisionMode.Certified)
    c.time_budget_seconds = float(o.time_budget)
    if int(o.memory_budget) < 0:
        raise ValueError("memory_budget must be >= 0")
    c.memory_budget_bytes = int(o.memory_budget)
    return c
