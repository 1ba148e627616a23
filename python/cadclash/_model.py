"""Loading files into a ``Model`` and reading it: parts, instances, surfaces and their triangles."""
from __future__ import annotations

import os
from typing import Dict, Iterable, List, Optional, Sequence, Tuple, Union

import numpy as np

from . import _cadclash as _core
from ._types import Diagnostic, InputError, Provenance, _diagnostics

__all__ = ["load", "Model", "Part", "Instance", "Surface"]

PathLike = Union[str, os.PathLike]


class Part:
    """A part: one shape (or one mesh file) with its surfaces, shared by all its instances."""

    __slots__ = ("model", "id", "name", "source_file", "surface_ids", "has_exact_geometry")

    def __init__(self, model: "Model", pid: int):
        name, source_file, first, count, has_source = model._part(pid)
        self.model = model
        self.id = pid
        self.name: str = name
        self.source_file: str = source_file
        self.surface_ids = range(first, first + count)   # surfaces of a part are contiguous
        self.has_exact_geometry: bool = has_source       # B-rep part: lazy tessellation and exact distances

    @property
    def surfaces(self) -> Tuple["Surface", ...]:
        return tuple(self.model.surfaces[s] for s in self.surface_ids)

    def __repr__(self) -> str:
        return f"Part({self.id}, {self.name!r}, {len(self.surface_ids)} surfaces)"


class Instance:
    """One placement of a part. ``path`` is the assembly path ("/as1/ROD-ASSEMBLY/NUT::1");
    ``pose`` is the imported part-local → world 4x4 matrix (a new array on every access; a
    ``Scene`` keeps its own poses)."""

    __slots__ = ("model", "id", "path", "part_id")

    def __init__(self, model: "Model", iid: int):
        path, part, _pose = model._instance(iid)
        self.model = model
        self.id = iid
        self.path: str = path
        self.part_id: int = part

    @property
    def part(self) -> Part:
        return self.model.parts[self.part_id]

    @property
    def pose(self) -> np.ndarray:
        return self.model._instance(self.id)[2]

    def __repr__(self) -> str:
        return f"Instance({self.id}, {self.path!r}, part={self.part.name!r})"


class Surface:
    """One tagged surface: a CAD face, an OBJ group, an OFF colour group or a whole mesh.

    Name, part and provenance are fixed after loading. ``vertices`` and ``triangles`` are
    read-only NumPy views of the model's own storage (no copy; ``arr.base`` is the model, which
    they keep alive). For a surface of a lazy load that has no triangles yet, the first access
    tessellates it in the model (at the load deflection) and then returns the view; a face that
    fails to mesh gives empty (0, 3) arrays and ``has_triangles`` stays False. Triangles, once
    present, are never replaced, so a view stays valid and unchanged for the model's lifetime.
    Vertices are part-local, millimetres; triangles index them counter-clockwise seen from outside.
    """

    __slots__ = ("model", "id", "name", "part_id", "provenance", "uncertainty", "uncertainty_source")

    def __init__(self, model: "Model", sid: int):
        (name, part, kind, source_file, step_id, face_index, source_name, parent, colour, healed, repaired,
         uncertainty, uncertainty_source) = model._surface(sid)
        self.model = model
        self.id = sid
        self.name: str = name
        self.part_id: int = part
        self.provenance = Provenance(kind, source_file, None if step_id < 0 else step_id, face_index, source_name,
                                     None if parent < 0 else parent, colour, healed, repaired)
        # The model uncertainty ε, mm (0: derived from the part's coordinates when a query runs), and
        # where it came from: "coordinates", "occt tolerance", "declared" or "given" (load's uncertainty).
        self.uncertainty: float = uncertainty
        self.uncertainty_source: str = uncertainty_source

    @property
    def part(self) -> Part:
        return self.model.parts[self.part_id]

    @property
    def step_id(self) -> Optional[int]:
        """STEP ``#id`` of the face entity; None for non-STEP surfaces."""
        return self.provenance.step_id

    @property
    def face_index(self) -> int:
        return self.provenance.face_index

    @property
    def colour(self) -> Optional[Tuple[float, float, float]]:
        return self.provenance.colour

    @property
    def has_triangles(self) -> bool:
        """False while a lazy surface has not been tessellated (or failed to mesh)."""
        return self.model._surface_state(self.id)[0]

    @property
    def deflection(self) -> float:
        """Achieved bound (mm) between the triangles and the exact face; 0 for meshes."""
        return self.model._surface_state(self.id)[1]

    @property
    def aabb(self) -> Optional[Tuple[Tuple[float, float, float], Tuple[float, float, float]]]:
        """Part-local ((min x, y, z), (max x, y, z)) enclosing the exact surface; None if empty."""
        return self.model._surface_state(self.id)[2]

    @property
    def vertices(self) -> np.ndarray:
        """(n, 3) float64, read-only view (see the class docstring)."""
        return self.model._vertices(self.id, True)

    @property
    def triangles(self) -> np.ndarray:
        """(m, 3) uint32 indices into ``vertices``, read-only view."""
        return self.model._triangles(self.id, True)

    def mesh(self, tessellate: bool = True) -> Tuple[np.ndarray, np.ndarray]:
        """(vertices, triangles). With ``tessellate=False`` a lazy surface is left as it is
        (empty arrays until something tessellates it)."""
        return self.model._vertices(self.id, tessellate), self.model._triangles(self.id, tessellate)

    def __repr__(self) -> str:
        tag = f" #{self.step_id}" if self.step_id is not None else ""
        return f"Surface({self.id}, {self.name!r}{tag}, part={self.part.name!r})"


class Model(_core.ModelCore):
    """A loaded scene: parts, surfaces and instances, indexed by small integer ids.

    Create with ``cadclash.load()``. ``diagnostics`` lists every problem of the input (each names the
    file and line or the STEP ``#id``); ``complete`` is False when any part of the input was dropped
    or failed to mesh. Everything that could be read is kept. The model is safe to share between
    threads: queries that write it (lazy tessellation) take its lock with the GIL released.
    """

    def __init__(self):
        super().__init__()
        self.files: List[str] = []
        self.diagnostics: List[Diagnostic] = []
        self.complete: bool = True
        self._parts: Optional[Tuple[Part, ...]] = None
        self._surfaces: Optional[Tuple[Surface, ...]] = None
        self._instances: Optional[Tuple[Instance, ...]] = None
        self._by_path: Optional[Dict[str, int]] = None
        self._name_cache = None

    @property
    def parts(self) -> Tuple[Part, ...]:
        if self._parts is None:
            self._parts = tuple(Part(self, i) for i in range(self._counts()[0]))
        return self._parts

    @property
    def surfaces(self) -> Tuple[Surface, ...]:
        if self._surfaces is None:
            self._surfaces = tuple(Surface(self, i) for i in range(self._counts()[1]))
        return self._surfaces

    @property
    def instances(self) -> Tuple[Instance, ...]:
        if self._instances is None:
            self._instances = tuple(Instance(self, i) for i in range(self._counts()[2]))
        return self._instances

    def instance(self, key: Union[int, str, Instance]) -> Instance:
        """The instance with this id or exact path. IndexError / KeyError when there is none."""
        return self.instances[self._instance_id(key)]

    def _instance_id(self, key) -> int:
        if isinstance(key, Instance):
            if key.model is not self:
                raise ValueError(f"instance {key.path!r} belongs to another model")
            return key.id
        if isinstance(key, str):
            if self._by_path is None:
                self._by_path = {inst.path: inst.id for inst in self.instances}
            try:
                return self._by_path[key]
            except KeyError:
                raise KeyError(f"no instance with path {key!r}") from None
        if isinstance(key, (int, np.integer)) and not isinstance(key, bool):
            if not 0 <= int(key) < len(self.instances):
                raise IndexError(f"instance id {int(key)} out of range (model has {len(self.instances)})")
            return int(key)
        raise TypeError(f"an instance is an id (int), a path (str) or an Instance; got {type(key).__name__}")

    def instances_under(self, prefix: str) -> List[Instance]:
        """Instances whose path is ``prefix`` or lies below it (the CLI's --select-a matching)."""
        return [i for i in self.instances if _path_under(i.path, prefix)]

    @property
    def triangle_count(self) -> int:
        """Triangles over all surfaces that have them."""
        return self._triangle_count()

    def tessellate(self, surfaces: Optional[Iterable[Union[int, Surface]]] = None,
                   deflection: Optional[float] = None, threads: int = 0) -> List[Diagnostic]:
        """Gives triangles to the listed surfaces (default: all) that have none yet (lazy loads);
        ``deflection`` defaults to the load deflection; parts are meshed on at most ``threads``
        threads at once (0: every core). Returns diagnostics for faces that failed."""
        ids = range(len(self.surfaces)) if surfaces is None else [s.id if isinstance(s, Surface) else int(s)
                                                                    for s in surfaces]
        return _diagnostics(self._tessellate(list(ids), 0.0 if deflection is None else float(deflection),
                                             int(threads)))

    def __repr__(self) -> str:
        return (f"Model({len(self.parts)} parts, {len(self.instances)} instances, {len(self.surfaces)} surfaces, "
                f"{len(self.diagnostics)} diagnostics)")

    # Caches of what results name, so building a Report does not cross into C++ per pair.
    def _names(self):
        if self._name_cache is None:
            self._name_cache = (
                [i.path for i in self.instances],
                [self.parts[i.part_id].name for i in self.instances],
                [s.name for s in self.surfaces],
                [s.step_id for s in self.surfaces],
            )
        return self._name_cache


def _path_under(path: str, prefix: str) -> bool:
    if not prefix or not path.startswith(prefix):
        return False
    return len(path) == len(prefix) or path[len(prefix)] == "/" or prefix.endswith("/")


def load(paths: Union[PathLike, Sequence[PathLike]], *, deflection: float = 0.1, angular: float = 0.5,
         relative: bool = False, preset: Optional[str] = None, lazy: bool = False, repair: bool = False,
         fill_holes: bool = False, segment: bool = False, sharp_angle: float = 60.0, planar: bool = False,
         isolate: bool = True, transfer_healing: bool = True, time_limit: float = 0.0, model_tolerance: float = 0.0,
         uncertainty: Union[str, float] = "auto", cache: Optional[PathLike] = None, threads: int = 0, strict: bool = False) -> Model:
    """Reads one or more files (STEP, IGES, BREP, OBJ, OFF, STL, PLY, glTF) into one ``Model``.

    The arguments mirror ``cadclash check``'s input switches: ``deflection`` (mm, or a fraction of
    each part's size with ``relative``), ``angular`` (radians), ``preset`` ("coarse", "normal",
    "fine", "very-fine"; overrides deflection and angular), ``lazy`` (B-rep faces get triangles only
    when a query or an array access needs them), ``repair`` / ``fill_holes`` and ``segment`` /
    ``sharp_angle`` / ``planar`` for mesh parts. ``isolate`` reads STEP/IGES/BREP in a forked child
    process, so a file that crashes OCCT gives an error diagnostic (and the faces that could still be
    read) instead of ending Python; ``isolate=False`` is the CLI's ``--no-isolation``.
    ``transfer_healing=False`` (the CLI's ``--no-transfer-healing``) skips OCCT's shape healing of
    every STEP/IGES shape at transfer: a faster import, faces BRepCheck rejects healed one by one
    (docs/import.md, "Healing at transfer"). ``time_limit``
    (seconds, 0 = none; the CLI's ``--import-time-limit``) stops an isolated reader that takes longer
    on one file, and then the file's tessellation, with error diagnostics naming what was not done.
    ``model_tolerance`` (mm; the CLI's ``--model-tolerance``) is the uncertainty of mesh coordinates
    (0: 2^-24 x the largest coordinate): faces within tolerance + both uncertainties touch.
    ``uncertainty`` (the CLI's ``--uncertainty``) says where a CAD face's uncertainty comes from:
    "auto" (the larger of its OCCT tolerance and the STEP file's declared uncertainty), "occt" (OCCT
    tolerances only), or a length in mm for every surface, meshes too (a CAD face keeps its OCCT
    tolerance when that is larger) (``Surface.uncertainty_source`` says which applied). ``cache``
    (a directory; the CLI's ``--cache``) keeps every file as imported, keyed by a SHA-256 of its bytes,
    path and these settings: a file loaded again unchanged comes back from it, the same model; a
    damaged entry is read again and named in a warning diagnostic. Several files form one scene,
    read in parallel; each file's instance paths are then prefixed with "/<file name>". ``threads``
    (the CLI's ``--threads``; 0 = every core) holds the whole load to that many threads: files read at
    once, parts meshed at once, and OCCT's meshing of a part's faces (its thread pool is
    process-wide: each load sets it). The model does not depend on it.

    Returns the model with ``diagnostics`` and ``complete`` set: a partly bad file keeps its good
    parts. Raises ``InputError`` (naming each file and line or STEP ``#id``) when no instance could
    be read, or with ``strict=True`` when any error was reported; ValueError for bad arguments.
    Runs with the GIL released; loads run one at a time (OCCT's readers share global settings).
    """
    if isinstance(paths, (str, os.PathLike)):
        paths = [paths]
    files = [os.fspath(p) for p in paths]
    model = Model()
    raw, complete = model._load(files, float(deflection), bool(relative), float(angular), preset or "",
                                bool(lazy), bool(repair), bool(fill_holes), bool(segment), float(sharp_angle),
                                bool(planar), bool(isolate), bool(transfer_healing), float(time_limit),
                                float(model_tolerance),
                                uncertainty if isinstance(uncertainty, str) else "value",
                                0.0 if isinstance(uncertainty, str) else float(uncertainty),
                                os.fspath(cache) if cache is not None else "", int(threads))
    model.files = files
    model.diagnostics = _diagnostics(raw)
    model.complete = complete
    if not model.instances:
        raise InputError(f"{', '.join(files)}: nothing could be loaded", model.diagnostics)
    if strict and any(d.is_error for d in model.diagnostics):
        raise InputError(f"{', '.join(files)}: errors while loading (strict=True)", model.diagnostics)
    return model
