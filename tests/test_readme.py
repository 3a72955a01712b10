"""The README's Python example runs as written (keeps the README true)."""
import re
from pathlib import Path

README = Path(__file__).resolve().parents[1] / "README.md"


def test_readme_python_blocks_run(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)   # the examples write their outputs where they run
    blocks = re.findall(r"```python\n(.*?)```", README.read_text(), re.S)
    assert blocks, "README has no Python example"
    for code in blocks:
        exec(compile(code, "README.md", "exec"), {})


def test_readme_test_command_is_what_ci_runs():
    ci = (README.parent / ".ci" / "run").read_text()
    cmd = re.search(r"Run the tests.*?\n\n\s+(.+?)\n", README.read_text(), re.S).group(1)
    assert cmd.strip() in ci


def test_readme_install_command_is_what_ci_runs():
    """CI's first step is a newcomer's: the README's install command, verbatim."""
    ci = (README.parent / ".ci" / "run").read_text()
    cmd = re.search(r"Install and run the demo.*?\n\n\s+(.+?)\n", README.read_text(), re.S).group(1)
    assert "pip install" in cmd
    assert cmd.strip() in ci


def test_readme_docs_commands_are_what_ci_runs():
    """The docs install and build commands the README gives, verbatim in CI."""
    ci = (README.parent / ".ci" / "run").read_text()
    text = " ".join(README.read_text().split())
    cmds = re.search(r"builds with `(.+?)` and `(.+?)`", text).groups()
    assert cmds[0].startswith("pip install") and cmds[1].startswith("python -m sphinx")
    for cmd in cmds:
        assert cmd in ci.splitlines(), cmd
