"""Scene / collide / replay: results against the CLI's JSON report, transforms, options."""
import math

import numpy as np
import pytest

import cadclash
from conftest import json_pair_key


def test_as1_pairs_match_cli_json(as1, as1_path, cli, tmp_path):
    report = cadclash.Scene(as1).check()
    j = cli(tmp_path, as1_path)
    assert {p.key for p in report} == {json_pair_key(p) for p in j["pairs"]}
    assert len(report) == len(j["pairs"]) > 0
    assert report.summary() == j["summary"]
    assert vars(report.counters) == j["counters"]
    assert report.diagnostics == []
    p = report.pairs[0]
    assert p.instance_a == as1.instances[p.instance_id_a].path
    assert p.step_id_a == as1.surfaces[p.surface_id_a].step_id
    assert p.part_a == as1.instances[p.instance_id_a].part.name


def test_selection_matches_cli(as1, as1_path, cli, tmp_path):
    scene = cadclash.Scene(as1, select_a="/as1/ROD-ASSEMBLY", exclude=["/as1/L-BRACKET-ASSEMBLY::1"])
    report = scene.check(tolerance=0.05, clearance=1.0)
    j = cli(tmp_path, as1_path, "--select-a", "/as1/ROD-ASSEMBLY", "--exclude-under", "/as1/L-BRACKET-ASSEMBLY::1",
            "--tolerance", "0.05", "--clearance", "1")
    assert {p.key for p in report} == {json_pair_key(p) for p in j["pairs"]}
    assert all(p.instance_a.startswith("/as1/ROD-ASSEMBLY") or p.instance_b.startswith("/as1/ROD-ASSEMBLY")
               for p in report)
    with pytest.raises(ValueError, match="select_b"):
        cadclash.Scene(as1, select_b="/as1/NOPE")


def test_results_do_not_depend_on_threads(as1):
    # Fresh scenes: the first check of a scene also places every instance box (aabb_updates).
    one = cadclash.Scene(as1).check(threads=1, parallel="v2")
    two = cadclash.Scene(as1).check(threads=2, parallel="v2")
    assert one.pairs == two.pairs and one.counters == two.counters


def test_set_transform_moves_a_part_into_collision_and_back(boxes):
    model = cadclash.load(boxes)
    scene = cadclash.Scene(model)
    near = "/box_near.obj/box_near"
    assert not scene.check().collision  # 0.5 apart
    assert scene.check(clearance=0.6).summary()["clearance"] > 0

    # Pushed 0.25 into box_a, offset in y and z so that faces cross (data/collide/path_ok.csv step 2).
    scene.set_transform(near, ((-0.75, 0.3, 0.2), (1, 0, 0, 0)))
    inside = scene.check()
    assert inside.count("penetrating") > 0
    assert all(p.instance_a == "/box_a.obj/box_a" and p.instance_b == near for p in inside)
    np.testing.assert_allclose(scene.transform(near)[:3, 3], [-0.75, 0.3, 0.2])
    assert model.instance(near).pose[0, 3] == 0.0  # the model's own pose is untouched

    # The same pose as a 4x4 matrix gives the same answer.
    scene.reset_transform(near)
    assert not scene.check().collision
    m = np.eye(4)
    m[:3, 3] = [-0.75, 0.3, 0.2]
    scene.set_transform(model.instance(near), m)
    assert scene.check().pairs == inside.pairs

    scene.set_transform(1, np.eye(4))
    assert not scene.check().collision


def test_rotation_as_quaternion(boxes):
    model = cadclash.load(boxes)
    scene = cadclash.Scene(model)
    # A quarter turn about z (unnormalised quaternion: normalised like a trajectory row).
    scene.set_transform(1, ((0.0, 0.0, 0.0), (2.0, 0.0, 0.0, 2.0)))
    r = scene.transform(1)[:3, :3]
    np.testing.assert_allclose(r, [[0, -1, 0], [1, 0, 0], [0, 0, 1]], atol=1e-12)


def test_bad_transforms(boxes):
    scene = cadclash.Scene(cadclash.load(boxes))
    with pytest.raises(ValueError, match="rotation"):
        scene.set_transform(1, np.diag([2.0, 1.0, 1.0, 1.0]))  # a scale is not rigid
    with pytest.raises(ValueError, match="last row"):
        scene.set_transform(1, np.ones((4, 4)))
    with pytest.raises(ValueError, match="4x4"):
        scene.set_transform(1, np.eye(3))
    with pytest.raises(ValueError, match="zero"):
        scene.set_transform(1, ((0, 0, 0), (0, 0, 0, 0)))
    with pytest.raises(ValueError, match="non-finite"):
        scene.set_transform(1, ((math.nan, 0, 0), (1, 0, 0, 0)))
    with pytest.raises(KeyError):
        scene.set_transform("/box_near", np.eye(4))


def test_options(boxes):
    scene = cadclash.Scene(cadclash.load(boxes))
    with pytest.raises(TypeError, match="tolerence"):
        scene.check(tolerence=0.1)
    with pytest.raises(ValueError, match="parallel"):
        scene.check(parallel="v3")
    with pytest.raises(ValueError, match="tolerance"):
        scene.check(tolerance=-1.0)
    opts = cadclash.CollideOptions(clearance=0.6)
    assert len(scene.check(opts)) == len(scene.check(clearance=0.6)) > 0
    assert len(scene.check(opts, clearance=0.0)) == 0  # a keyword overrides the object's field


def test_all_triangles_lists_triangle_pairs(boxes):
    model = cadclash.load(boxes)
    scene = cadclash.Scene(model)
    scene.set_transform(1, ((-0.75, 0.3, 0.2), (1, 0, 0, 0)))
    report = scene.check(all_triangles=True)
    hit = [p for p in report if p.intersecting]
    assert hit
    for p in hit:
        assert p.triangle_pairs.dtype == np.uint32 and p.triangle_pairs.shape[1] == 2 and len(p.triangle_pairs) > 0
        assert p.triangle_pairs[:, 0].max() < len(model.surfaces[p.surface_id_a].triangles)


def test_one_off_collide_matches_scene(as1):
    report = cadclash.Scene(as1).check()
    p = report.pairs[0]
    one = cadclash.collide(as1, p.instance_a, p.instance_id_b)
    assert one.pairs == [q for q in report if (q.instance_id_a, q.instance_id_b) == (p.instance_id_a, p.instance_id_b)]
    with pytest.raises(ValueError, match="different"):
        cadclash.collide(as1, 0, 0)


def test_replay_matches_cli(boxes, data_dir, cli, tmp_path):
    csv = data_dir / "collide" / "path_ok.csv"
    model = cadclash.load(boxes)
    run = cadclash.replay(cadclash.Scene(model), csv)
    j = cli(tmp_path, *boxes, "--path", csv)
    assert [s.step for s in run] == [s["step"] for s in j["steps"]] == [0, 1, 2]
    for mine, theirs in zip(run, j["steps"]):
        assert {p.key for p in mine.report} == {json_pair_key(p) for p in theirs["pairs"]}
        assert mine.report.summary() == theirs["summary"]
    assert not run.steps[0].report.collision and run.steps[2].report.count("penetrating") > 0


def test_replay_bad_row_names_file_and_line(boxes, data_dir):
    scene = cadclash.Scene(cadclash.load(boxes))
    bad = data_dir / "collide" / "path_bad.csv"
    with pytest.raises(cadclash.InputError) as e:
        cadclash.replay(scene, bad)
    first = e.value.diagnostics[0]
    assert first.file == str(bad) and first.line > 0 and f"path_bad.csv:{first.line}: error" in str(e.value)
    with pytest.raises(cadclash.InputError, match="missing.csv"):
        cadclash.replay(scene, data_dir / "collide" / "missing.csv")


def test_replay_unknown_instance_is_a_warning(boxes, tmp_path):
    csv = tmp_path / "path.csv"
    csv.write_text("0,/box_near.obj/box_near,-0.5,0,0,1,0,0,0\n0,/nobody,0,0,0,1,0,0,0\n")
    run = cadclash.replay(cadclash.Scene(cadclash.load(boxes)), csv)
    assert len(run) == 1 and run.steps[0].report.count("touching") > 0
    assert [(d.severity, d.line) for d in run.diagnostics] == [("warning", 2)]


def test_memory_budget_gives_a_partial_report(as1_path):
    model = cadclash.load(as1_path, lazy=True)
    full = cadclash.Scene(model).check()
    assert full.complete and full.stopped_by == "" and full.unexamined_pairs == [] and full.memory_charged > 0
    lazy = cadclash.load(as1_path, lazy=True)
    part = cadclash.Scene(lazy).check(memory_budget=full.memory_charged // 2)
    assert not part.complete and part.stopped_by == "memory budget"
    assert 0 < len(part) < len(full) and part.unexamined_pairs
    assert {p.key for p in part} <= {p.key for p in full}
