"""cadclash: which surfaces of which parts of a CAD assembly intersect or touch?

Python bindings of the cadclash C++ library (see docs/python.md)::

    import cadclash
    model = cadclash.load("as1-tu-203.stp")          # InputError if nothing could be read
    scene = cadclash.Scene(model)                      # prepared once
    report = scene.check(tolerance=0.01)               # GIL released while it runs
    for p in report:                                   # plain PairResult values
        print(p.contact, p.instance_a, p.step_id_a, p.instance_b, p.step_id_b)

Contracts:
- Ids are small integers indexing ``model.parts``, ``model.surfaces``, ``model.instances``; units
  are millimetres.
- Bad input files never crash: problems come back as ``Diagnostic`` values naming the file and line
  or the STEP ``#id``; ``InputError`` is raised only when nothing usable is left.
- ``Surface.vertices`` / ``Surface.triangles`` are read-only zero-copy NumPy views kept alive by the
  model; results (``Report``, ``PairResult``, ...) are snapshots that own their data.
- Queries (``Scene.check``, ``collide``, ``replay``, ``load``) release the GIL; results do not depend
  on the thread count.
"""
from ._types import (ClosestApproach, Counters, Diagnostic, InputError, ModelMemory, PairResult, PairTimeline, Provenance, Replay,
                     Report, StepResult, SurfaceTimeline, Timeline, TimelineSpan, Timings)
from ._options import CollideOptions
from ._model import Instance, Model, Part, Surface, load
from ._scene import Scene, collide, replay

__all__ = [
    "load", "Model", "Part", "Instance", "Surface", "Provenance",
    "Scene", "collide", "replay", "CollideOptions",
    "Report", "PairResult", "Counters", "Timings", "ModelMemory", "StepResult", "Replay", "Timeline", "PairTimeline",
    "SurfaceTimeline", "TimelineSpan", "ClosestApproach", "Diagnostic",
    "InputError",
]
__version__ = "0.1.0"
