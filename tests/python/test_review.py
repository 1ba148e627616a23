"""Report.review / clashes / collision with approvals against `cadclash check --baseline --approvals`
(docs/review.md), byte for byte."""
import json
import os
import subprocess

import pytest

import cadclash


def _cli(tmp_path, *args):
    exe = os.environ.get("CADCLASH_EXE")
    if not exe or not os.path.isfile(exe):
        pytest.skip("CADCLASH_EXE is not set to the built cadclash tool")
    out = tmp_path / f"report{len(list(tmp_path.iterdir()))}.json"
    proc = subprocess.run([exe, "check", *map(str, args), "--eager", "--json", str(out), "--no-timings"],
                          capture_output=True, text=True)
    assert proc.returncode in (0, 3), proc.stderr
    return out


def test_clashes_group_pairs_and_start_new(as1):
    report = cadclash.Scene(as1).check()
    clashes = report.clashes
    assert len(clashes) == 32
    assert all(c["status"] == "new" and c["approval"] is None for c in clashes)
    assert sum(len(c["surface_pairs"]) for c in clashes) == len(report.pairs)
    assert report.review_summary["summary"]["new"] == 32
    assert report.collision


def test_review_matches_the_cli_byte_for_byte(as1, as1_path, boxes, tmp_path):
    baseline_file = _cli(tmp_path, *boxes)  # the boxes: every as1 clash is new, every box clash resolved
    first = cadclash.Scene(as1).check().clashes[0]["id"]
    approvals = tmp_path / "approvals.json"
    approvals.write_text(json.dumps({"schema": "cadclash-approvals", "version": 1, "approvals": [
        {"id": first, "reason": "designed", "by": "py", "date": "2026-01-01"},
        {"part_a": "bolt", "part_b": "plate", "classes": ["touching"], "reason": "fasteners", "by": "py",
         "date": "2026-01-01", "expires": "2026-03-01"}]}))
    cli = _cli(tmp_path, as1_path, "--baseline", baseline_file, "--approvals", approvals, "--today", "2026-02-01",
               "--group-by", "subassembly")
    baseline = cadclash.Report.from_json(baseline_file.read_text())
    reviewed = cadclash.Scene(as1).check().review(baseline=baseline, approvals=approvals, today="2026-02-01",
                                                  group_by="subassembly", baseline_file=str(baseline_file))
    assert reviewed.to_json() == cli.read_text()
    summary = reviewed.review_summary["summary"]
    assert summary["resolved"] == len(baseline.clashes) and summary["approved"] >= 1
    assert reviewed.collision  # not every clash is approved
    # Reviewing against itself: every clash active; an approve-everything rule clears the collision.
    everything = tmp_path / "everything.json"
    everything.write_text(json.dumps({"schema": "cadclash-approvals", "version": 1, "approvals": [
        {"a": "**", "reason": "all", "by": "py", "date": "2026-01-01"}]}))
    again = reviewed.review(baseline=reviewed, approvals=everything, today="2026-02-01")
    assert {c["status"] for c in again.clashes} == {"active"}
    assert not again.collision


def test_bad_approvals_name_the_field(as1, tmp_path):
    bad = tmp_path / "bad.json"
    bad.write_text('{"schema": "cadclash-approvals", "version": 1, "approvals": [{"id": "x", "by": "b", "date": "2026-01-01"}]}')
    with pytest.raises(ValueError, match=r"bad.json: /approvals/0/reason: is missing"):
        cadclash.Scene(as1).check().review(approvals=bad)
    with pytest.raises(ValueError, match="group_by"):
        cadclash.Scene(as1).check().review(group_by="colour")
