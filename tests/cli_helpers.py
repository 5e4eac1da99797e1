"""Helpers shared by the command-line guard tests: run the CLI and check a one-line refusal."""

from __future__ import annotations

from msslib import cli


def run_cli(capsys, *argv):
    """``(exit code, stderr)`` of ``python -m msslib ARGV``, run in this process."""
    code = cli.main([str(a) for a in argv])
    return code, capsys.readouterr().err


def assert_refused(code, err, *names):
    """Exit code 1 and exactly one ``msslib: error:`` line naming every one of ``names``, with no
    internal temporary file in it."""
    lines = err.splitlines()
    assert code == 1, err
    assert len(lines) == 1, err
    assert lines[0].startswith("msslib: error:"), err
    for name in names:
        assert str(name) in lines[0], (name, err)
    assert "msslib-tmp" not in err
