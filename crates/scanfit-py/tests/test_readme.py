"""The README's Python example runs as printed (doctest of its code block)."""

import doctest
import os
import re
import warnings

from conftest import ROOT


def test_readme_python_example(tmp_path, monkeypatch):
    text = (ROOT / "README.md").read_text()
    section = text[text.index("## Python\n"):]
    block = re.search(r"```python\n(.*?)```", section, re.S).group(1)
    (tmp_path / "examples").symlink_to(ROOT / "examples")
    monkeypatch.chdir(tmp_path)
    test = doctest.DocTestParser().get_doctest(block, {}, "README ## Python", "README.md", 0)
    runner = doctest.DocTestRunner(optionflags=doctest.NORMALIZE_WHITESPACE)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the example's fit stays inside the data
        runner.run(test)
    result = runner.summarize(verbose=False)
    assert result.failed == 0 and result.attempted >= 10, result
    assert (tmp_path / "patch.stp").read_text().count("B_SPLINE_SURFACE_WITH_KNOTS") == 1
    assert os.path.getsize(tmp_path / "patch.stp") > 1000
