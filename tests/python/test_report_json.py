"""Report.to_json / Report.from_json against `cadclash check --json`, byte for byte."""
import json
import os
import subprocess

import pytest

import cadclash


@pytest.fixture(scope="module")
def cli_text(tmp_path_factory):
    """Runs `cadclash check FILES... ARGS... --json OUT` and returns OUT's text."""
    exe = os.environ.get("CADCLASH_EXE")
    if not exe or not os.path.isfile(exe):
        pytest.skip("CADCLASH_EXE is not set to the built cadclash tool")

    def run(files, *args, timings=False):
        out = tmp_path_factory.mktemp("cli") / "report.json"
        # --eager unless --lazy: the Python models here load eagerly (load's default) unless they ask
        # for lazy; a check meshes lazily by default.
        mode = [] if "--lazy" in map(str, args) else ["--eager"]
        cmd = [exe, "check", *map(str, files), *map(str, args), *mode, "--json", str(out)]
        proc = subprocess.run(cmd + ([] if timings else ["--no-timings"]), capture_output=True, text=True)
        assert proc.returncode in (0, 3, 4), proc.stderr
        return out.read_text()

    return run


def _same_text(python_text, cli_text):
    assert python_text == cli_text  # byte for byte; on failure pytest shows the first difference


def test_as1_default_is_byte_identical_and_round_trips(as1, as1_path, cli_text):
    report = cadclash.Scene(as1).check()
    text = cli_text([as1_path])
    _same_text(report.to_json(), text)
    back = cadclash.Report.from_json(text)
    assert back.to_json() == text
    assert back.summary() == report.summary() and back.counters == report.counters
    assert [p.key for p in back] == [p.key for p in report]
    assert back.pairs[0].instance_id_a is None and back.pairs[0].step_id_a == report.pairs[0].step_id_a


def test_as1_options_and_selection(as1, as1_path, cli_text):
    scene = cadclash.Scene(as1, select_a="/as1/ROD-ASSEMBLY", exclude=["/as1/L-BRACKET-ASSEMBLY::1"])
    report = scene.check(tolerance=0.05, clearance=1.0, fast=True, parallel="v2", schedule="static",
                         triangle_level="bvh")
    text = cli_text([as1_path], "--select-a", "/as1/ROD-ASSEMBLY", "--exclude-under", "/as1/L-BRACKET-ASSEMBLY::1",
                    "--tolerance", "0.05", "--clearance", "1", "--fast", "--parallel", "v2", "--schedule", "static",
                    "--triangle-level", "bvh")
    _same_text(report.to_json(), text)
    assert cadclash.Report.from_json(text).to_json() == text


def test_instance_ids_in_a_selection_are_written_as_paths(as1, as1_path, cli_text):
    rod = as1.instance("/as1/ROD-ASSEMBLY/ROD")
    report = cadclash.Scene(as1, select_a=[rod.id]).check()
    _same_text(report.to_json(), cli_text([as1_path], "--select-a", rod.path))


def test_partial_report_under_a_memory_budget(as1, as1_path, cli_text):
    report = cadclash.Scene(as1).check(memory_budget=512 * 1024)
    assert not report.complete
    text = cli_text([as1_path], "--memory-budget", "0.5")
    _same_text(report.to_json(), text)
    back = cadclash.Report.from_json(text)
    assert back.stopped_by == "memory budget" and back.to_json() == text


def test_preset_and_lazy_load(as1_path, cli_text):
    model = cadclash.load(as1_path, preset="coarse", lazy=True)
    _same_text(cadclash.Scene(model).check().to_json(), cli_text([as1_path], "--preset", "coarse", "--lazy"))


def test_meshes_with_every_triangle_pair(boxes, data_dir, cli_text):
    files = boxes + [data_dir / "collide" / "box_overlap.obj"]
    model = cadclash.load([str(f) for f in files])
    report = cadclash.Scene(model).check(all_triangles=True, clearance=1.0)
    text = cli_text(files, "--all-triangles", "--clearance", "1")
    assert '"triangle_pairs"' in text and '"source_name"' in text
    _same_text(report.to_json(), text)
    back = cadclash.Report.from_json(text)
    assert back.to_json() == text
    assert [p.triangle_pairs.tolist() for p in back] == [p.triangle_pairs.tolist() for p in report]


def test_timings_round_trip(boxes, cli_text):
    report = cadclash.Scene(cadclash.load([str(b) for b in boxes])).check(clearance=1.0)
    with_timings = report.to_json(timings=True)
    assert '"timings"' in with_timings and '"timings"' not in report.to_json()
    assert cadclash.Report.from_json(with_timings).to_json(timings=True) == with_timings
    text = cli_text(boxes, "--clearance", "1", timings=True)
    assert cadclash.Report.from_json(text).to_json(timings=True) == text


def test_diagnostics_are_parsed_back(tmp_path, data_dir):
    bad = tmp_path / "bad.obj"
    bad.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 9\n")
    model = cadclash.load([str(data_dir / "collide" / "box_a.obj"), str(bad)])
    text = cadclash.Scene(model).check().to_json()
    back = cadclash.Report.from_json(text)
    assert model.diagnostics and [str(d) for d in back.diagnostics] == [str(d) for d in model.diagnostics]
    assert [(d.file, d.line, d.severity) for d in back.diagnostics] == \
        [(d.file, d.line, d.severity) for d in model.diagnostics]
    assert back.to_json() == text


def test_malformed_reports_name_the_json_path(boxes):
    text = cadclash.Scene(cadclash.load([str(b) for b in boxes])).check(clearance=1.0).to_json()
    assert '"class": "clearance"' in text
    bad = json.loads(text)
    bad["pairs"][0]["class"] = "nearby"  # (the text's first "class" is now in `clashes`, which sorts first)
    with pytest.raises(ValueError, match=r"/pairs/0/class: unknown contact class 'nearby'"):
        cadclash.Report.from_json(json.dumps(bad))
    with pytest.raises(ValueError, match=r"/clashes/0/class: unknown contact class 'nearby'"):
        cadclash.Report.from_json(text.replace('"class": "clearance"', '"class": "nearby"', 1))
    with pytest.raises(ValueError, match="/version"):
        cadclash.Report.from_json(text.replace('"version": 2', '"version": 7'))
    with pytest.raises(ValueError, match="not valid JSON"):
        cadclash.Report.from_json(text[:-10])


def test_a_trajectory_report_is_not_one_query(boxes, data_dir, cli_text):
    text = cli_text(boxes, "--path", data_dir / "collide" / "path_ok.csv")
    with pytest.raises(ValueError, match="trajectory"):
        cadclash.Report.from_json(text)


def test_a_report_built_by_hand_has_no_document():
    report = cadclash.Report([], cadclash.Counters(), cadclash.Timings(), [])
    with pytest.raises(ValueError, match="no JSON document"):
        report.to_json()


def test_names_come_from_the_library():
    assert cadclash.Report([], cadclash.Counters(), cadclash.Timings(), []).summary() == {
        "pairs": 0, "penetrating": 0, "touching": 0, "clearance": 0, "containment": 0, "undecided": 0,
        "decided_by": {"mesh": 0, "mesh-exact": 0, "analytic": 0, "refined": 0, "exact": 0, "undecided": 0},
        "contact_within": {"unknown": 0, "tolerance": 0, "model uncertainty": 0}}
    assert len(vars(cadclash.Counters())) == 24


def test_replay_is_byte_identical_to_check_path(boxes, data_dir, cli_text):
    csv = str(data_dir / "collide" / "path_ok.csv")
    scene = cadclash.Scene(cadclash.load([str(b) for b in boxes]))
    replayed = cadclash.replay(scene, csv, clearance=0.2)
    text = cli_text(boxes, "--path", csv, "--clearance", "0.2")
    assert '"steps"' in text and len(replayed) > 1
    _same_text(replayed.to_json(), text)


def test_a_trajectory_report_reads_back_as_a_replay(boxes, data_dir, cli_text):
    csv = str(data_dir / "collide" / "path_ok.csv")
    scene = cadclash.Scene(cadclash.load([str(b) for b in boxes]))
    replayed = cadclash.replay(scene, csv, clearance=0.2)
    text = cli_text(boxes, "--path", csv, "--clearance", "0.2")
    back = cadclash.Replay.from_json(text)
    assert back.to_json() == text
    assert [s.step for s in back] == [s.step for s in replayed]
    for read, live in zip(back, replayed):
        assert [p.key for p in read.report] == [p.key for p in live.report]
        assert read.report.counters == live.report.counters
        assert read.report.model == live.report.model and read.report.complete
        assert [p.distance for p in read.report] == [p.distance for p in live.report]
    assert back.steps_not_checked == 0
    with pytest.raises(ValueError, match="Report.from_json"):
        cadclash.Replay.from_json(cadclash.Scene(cadclash.load([str(b) for b in boxes])).check().to_json())


def test_continuous_replay_is_byte_identical_to_check_path_continuous(boxes, data_dir, cli_text):
    """replay(continuous=True) writes what `cadclash check --path --continuous` writes, byte for byte,
    and the report reads back with its timeline: the near box comes within 0.01 of box_a at t = 0.98
    (a span at most 1/1000 of the stretch wide brackets it), then stays in contact to the last step."""
    csv = str(data_dir / "collide" / "path_ok.csv")
    scene = cadclash.Scene(cadclash.load([str(b) for b in boxes]))
    replayed = cadclash.replay(scene, csv, tolerance=0.01, continuous=True)
    text = cli_text(boxes, "--path", csv, "--tolerance", "0.01", "--continuous")
    _same_text(replayed.to_json(), text)
    t = replayed.timeline
    assert t is not None and t.complete and t.resolution == 1e-3 and t.checks > 0
    assert len(t.pairs) == 1 and t.pairs[0].surfaces
    first, last = t.pairs[0].spans[0], t.pairs[0].spans[-1]
    assert first.t0 <= 0.98 <= first.t1 and first.t1 - first.t0 <= 1e-3 + 1e-12 and not first.contact_at_ends
    assert last.t1 == 2.0 and last.contact_at_ends
    side = t.pairs[0].surfaces[0].a
    assert side[0] == t.pairs[0].a and side[2]  # instance path, part, surface name
    back = cadclash.Replay.from_json(text)
    assert back.to_json() == text and back.timeline == t
    assert cadclash.replay(scene, csv, tolerance=0.01).timeline is None
    with pytest.raises(ValueError, match="time_resolution"):
        cadclash.replay(scene, csv, continuous=True, time_resolution=0)


def test_model_bytes_match_the_json_report(as1, as1_path, cli_text):
    import json
    report = cadclash.Scene(as1).check()
    model = json.loads(cli_text([as1_path]))["model"]
    assert report.model.triangle_count == model["triangles"] > 0
    assert report.model.total == model["bytes"]["total"]
    for k in ("triangles", "vertices", "hierarchies", "instances"):
        assert getattr(report.model, k) == model["bytes"][k] > 0
    assert cadclash.Report.from_json(report.to_json()).model == report.model
    assert report.model.bytes_per_triangle == report.model.total / report.model.triangle_count


@pytest.mark.parametrize("preset,deflection,angular", [("coarse", 1.0, 0.8), ("normal", 0.1, 0.5),
                                                      ("fine", 0.01, 0.25)])
@pytest.mark.parametrize("lazy", [False, True])
def test_presets_equal_their_explicit_deflections(as1_path, preset, deflection, angular, lazy):
    """A preset is resolved once, before anything reads it (issue 19): load(preset=P) reports what
    load(deflection=d, angular=a) of that preset reports, with and without lazy tessellation, and
    the settings show the deflections in effect."""
    import json
    by_preset = json.loads(cadclash.Scene(cadclash.load(as1_path, preset=preset, lazy=lazy)).check().to_json())
    explicit = json.loads(cadclash.Scene(cadclash.load(as1_path, deflection=deflection, angular=angular,
                                                       lazy=lazy)).check().to_json())
    assert by_preset["pairs"] == explicit["pairs"] and by_preset["pairs"]
    assert by_preset["settings"]["preset"] == preset and explicit["settings"]["preset"] is None
    for doc in (by_preset, explicit):
        assert doc["settings"]["deflection"] == deflection
        assert doc["settings"]["angular_deflection"] == angular
        assert doc["settings"]["lazy"] == lazy
    assert all(p[side]["deflection"] <= deflection for p in by_preset["pairs"] for side in ("a", "b"))
