"""Runs the worked example of docs/python.md as a doctest, from the repository root."""
import doctest

from conftest import SOURCE_DIR


def test_worked_example(as1_path, monkeypatch):  # as1_path: skips without data/external
    monkeypatch.chdir(SOURCE_DIR)
    result = doctest.testfile(str(SOURCE_DIR / "docs" / "python.md"), module_relative=False,
                              optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE, verbose=False)
    assert result.attempted > 10
    assert result.failed == 0
