"""cadclash.load(): model inspection, diagnostics, and bad input."""
import numpy as np
import pytest

import cadclash


def test_mesh_files_form_one_scene(boxes):
    model = cadclash.load(boxes)
    assert model.complete and model.diagnostics == []
    assert [i.path for i in model.instances] == ["/box_a.obj/box_a", "/box_near.obj/box_near"]
    assert [p.name for p in model.parts] == ["box_a", "box_near"]
    part = model.parts[0]
    assert not part.has_exact_geometry
    assert len(part.surfaces) == 6  # one OBJ group per cube face
    s = part.surfaces[0]
    assert s.provenance.kind == "obj-group"
    assert s.provenance.source_file.endswith("box_a.obj")
    assert s.step_id is None and s.face_index == 0 and s.has_triangles and s.deflection == 0.0
    assert model.instance("/box_near.obj/box_near").part is model.parts[1]
    np.testing.assert_array_equal(model.instances[0].pose, np.eye(4))
    assert model.triangle_count == sum(len(s.triangles) for s in model.surfaces)


def test_step_provenance(as1):
    assert as1.complete, [str(d) for d in as1.diagnostics]
    assert len(as1.instances) == 18
    paths = {i.path for i in as1.instances}
    assert "/as1/L-BRACKET-ASSEMBLY::2/NUT-BOLT-ASSEMBLY::1/BOLT" in paths
    for part in as1.parts:
        assert part.has_exact_geometry
        for k, s in enumerate(part.surfaces):
            assert s.provenance.kind == "step-face"
            assert s.step_id is not None and s.step_id > 0
            assert s.face_index == k  # faces in TopExp::MapShapes order
            assert s.part is part
            assert s.deflection >= 0.0  # 0 (or rounding) for planar faces
            lo, hi = s.aabb
            assert all(a <= b for a, b in zip(lo, hi))
    assert max(s.deflection for s in as1.surfaces) > 0.0  # the curved ones
    step_ids = [s.step_id for s in as1.surfaces]
    assert len(set(step_ids)) == len(step_ids)  # one ADVANCED_FACE per surface
    assert all(s.colour is None or len(s.colour) == 3 for s in as1.surfaces)


def test_instance_lookup_errors(boxes):
    model = cadclash.load(boxes)
    with pytest.raises(KeyError, match="/nope"):
        model.instance("/nope")
    with pytest.raises(IndexError):
        model.instance(7)
    with pytest.raises(TypeError):
        model.instance(1.5)


def test_unreadable_file_raises_naming_file_and_line(data_dir):
    path = data_dir / "bad" / "garbage.obj"
    with pytest.raises(cadclash.InputError) as e:
        cadclash.load(path)
    assert "garbage.obj:1: error: binary data" in str(e.value)
    assert e.value.diagnostics[0].file == str(path) and e.value.diagnostics[0].line == 1


def test_missing_file_raises_naming_it(tmp_path):
    missing = tmp_path / "no_such.stp"
    with pytest.raises(cadclash.InputError, match="no_such.stp"):
        cadclash.load(missing)


def test_bad_step_names_entity(data_dir):
    with pytest.raises(cadclash.InputError) as e:
        cadclash.load(data_dir / "bad" / "step_garbage.step")
    assert "step_garbage.step: error: cannot read STEP file" in str(e.value)


def test_partly_bad_file_keeps_good_parts(data_dir):
    path = data_dir / "bad" / "truncated.obj"
    model = cadclash.load(path)
    assert not model.complete
    assert len(model.surfaces) == 2
    errors = [d for d in model.diagnostics if d.is_error]
    assert errors and errors[0].line == 9 and "truncated.obj:9: error: face dropped" in str(errors[0])
    with pytest.raises(cadclash.InputError, match="truncated.obj:9"):
        cadclash.load(path, strict=True)


def test_step_diagnostic_carries_step_id(data_dir):
    try:
        model = cadclash.load(data_dir / "cad" / "dangling_ref.step")
        diagnostics = model.diagnostics
    except cadclash.InputError as e:
        diagnostics = e.diagnostics
    assert any(d.step_id == 449 and "dangling_ref.step: #449: error" in str(d) for d in diagnostics)


def test_step_that_crashes_occt_is_contained(data_dir):
    # OCCT's transfer dereferences the LINE whose point was cut off (SIGSEGV): read in a child, the
    # crash is an error and the one good face is kept. Without isolation this test would kill Python.
    model = cadclash.load(data_dir / "fuzz-regressions" / "step_truncated_line_without_point.step")
    assert not model.complete
    assert any("OCCT crashed with SIGSEGV" in d.message for d in model.diagnostics)
    assert [s.step_id for s in model.surfaces] == [17]


def test_time_limit_stops_the_isolated_reader(data_dir):
    # Two solids cannot be parsed and transferred in a millisecond: the reader is stopped, an error
    # names the limit, and nothing is read; a generous limit changes nothing.
    step = data_dir / "cad" / "valid_two_solids.step"
    with pytest.raises(cadclash.InputError) as stopped:
        cadclash.load(step, time_limit=0.001)
    assert any("did not finish within the time limit of 0.001 s" in d.message for d in stopped.value.diagnostics)
    assert len(cadclash.load(step, time_limit=60).surfaces) == len(cadclash.load(step).surfaces)


def test_cache_gives_back_the_same_model(data_dir, tmp_path):
    # The first load reads the file and stores it; the second comes from the cache: the same
    # surfaces, triangles and diagnostics. A damaged entry is read again, with a warning.
    step = data_dir / "cad" / "valid_two_solids.step"
    cold = cadclash.load(step, cache=tmp_path / "cache")
    warm = cadclash.load(step, cache=tmp_path / "cache")
    entries = list((tmp_path / "cache").iterdir())
    # The file's entry and one per checked and healed B-rep part (docs/import.md, "A cache per product").
    assert len(entries) == 1 + len(cold.parts)
    entries = [e for e in entries if b"\nfile sha256 " in e.read_bytes()]
    assert len(entries) == 1
    assert [s.name for s in warm.surfaces] == [s.name for s in cold.surfaces]
    assert all((a.vertices == b.vertices).all() and (a.triangles == b.triangles).all()
               for a, b in zip(cold.surfaces, warm.surfaces))
    assert [d.message for d in warm.diagnostics] == [d.message for d in cold.diagnostics]
    entries[0].write_bytes(entries[0].read_bytes()[:100])
    again = cadclash.load(step, cache=tmp_path / "cache")
    assert any("is damaged" in d.message for d in again.diagnostics)
    assert len(again.surfaces) == len(cold.surfaces)


def test_without_healing_at_transfer_healed_faces_are_named(as1_path):
    # OCCT's healing at transfer skipped (the CLI's --no-transfer-healing): the faces BRepCheck then
    # rejects are healed one by one, each named with its STEP #id; the same faces as with it.
    healed = cadclash.load(as1_path, lazy=True)
    as_translated = cadclash.load(as1_path, lazy=True, transfer_healing=False)
    named = [d for d in as_translated.diagnostics if "failed BRepCheck; healed with ShapeFix_Face" in d.message]
    assert named and all(d.step_id > 0 for d in named)
    assert not any("failed BRepCheck" in d.message for d in healed.diagnostics)
    assert [s.step_id for s in as_translated.surfaces] == [s.step_id for s in healed.surfaces]


def test_bad_arguments(boxes):
    with pytest.raises(ValueError, match="preset"):
        cadclash.load(boxes, preset="ultra")
    with pytest.raises(ValueError, match="deflection"):
        cadclash.load(boxes, deflection=0.0)
    with pytest.raises(ValueError, match="time_limit"):
        cadclash.load(boxes, time_limit=-1)


def test_mesh_post_processing_switches(data_dir):
    flipped = data_dir / "repair" / "flipped_box.obj"
    assert not any(s.provenance.repaired for s in cadclash.load(flipped).surfaces)
    assert any(s.provenance.repaired for s in cadclash.load(flipped, repair=True).surfaces)

    cube = cadclash.load(data_dir / "mesh" / "cube_binary.stl", segment=True)
    assert [s.name for s in cube.surfaces] == [f"mesh-0/patch-{k}" for k in range(6)]
    assert all(s.provenance.kind == "segment" and s.provenance.parent == 0 for s in cube.surfaces)


def test_off_colours(data_dir):
    model = cadclash.load(data_dir / "mesh" / "colours.off")
    assert [(s.name, s.colour) for s in model.surfaces] == [("colour-FF0000", (1.0, 0.0, 0.0)),
                                                            ("colour-0000FF", (0.0, 0.0, 1.0))]


@pytest.mark.parametrize("preset,deflection,angular", [("coarse", 1.0, 0.8), ("normal", 0.1, 0.5), ("fine", 0.01, 0.25)])
@pytest.mark.parametrize("lazy", [False, True])
def test_preset_equals_its_explicit_deflections(as1_path, preset, deflection, angular, lazy):
    """load(preset=) is the explicit deflections of that preset, eager or lazy: the same pairs, and every
    face a query tessellated is meshed at the preset's deflection (lazy faces at the load deflection,
    not at load()'s default 0.1 mm)."""
    by_preset = cadclash.load(as1_path, preset=preset, lazy=lazy)
    explicit = cadclash.load(as1_path, deflection=deflection, angular=angular, lazy=lazy)
    ra = cadclash.Scene(by_preset).check()
    rb = cadclash.Scene(explicit).check()
    assert [(p.key, p.distance, p.decided_by) for p in ra.pairs] == [(p.key, p.distance, p.decided_by) for p in rb.pairs]
    assert ra.pairs
    meshed = [(a.deflection, b.deflection) for a, b in zip(by_preset.surfaces, explicit.surfaces) if a.has_triangles]
    assert meshed
    assert all(da == db for da, db in meshed)
    assert max(da for da, _ in meshed) <= deflection
