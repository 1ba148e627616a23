"""Runs the worked example of docs/python.md as a doctest, from the repository root."""
import doctest

from conftest import SOURCE_DIR


def test_worked_example(as1_path, monkeypatch):  # as1_path: skips without data/external
    monkeypatch.chdir(SOURCE_DIR)
    result = doctest.testfile(str(SOURCE_DIR / "docs" / "python.md"), module_relative=False,
                              optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE, verbose=False)
    assert result.attempted > 10
    assert result.failed == 0


def test_readme_python_block(as1_path, monkeypatch):
    """The README's Python lines, run where the sample assembly is: they load it and find its pairs."""
    import re
    text = (SOURCE_DIR / "README.md").read_text(encoding="utf-8")
    blocks = re.findall(r"```python\n(.*?)```", text, flags=re.S)
    assert len(blocks) == 1
    monkeypatch.chdir(as1_path.parent)
    scope = {}
    exec(compile(blocks[0], "README.md", "exec"), scope)
    assert len(scope["report"].pairs) > 0
