"""msslib.mesh.read silences meshio without replacing sys.stdout / sys.stderr: threads may read at
once, and what meshio says comes back as a warning (or in the error) instead of on the terminal."""

from __future__ import annotations

import sys
import threading

import meshio
import numpy as np
import pytest

from msslib import mesh as M
from msslib.errors import MsslibWarning

GRID = M.hex_grid(0.2, 0.1, 0.1, 2, 1, 1)


def _chatty_gmsh(path):
    """A gmsh 2.2 file that meshio reads but warns about: a last block without its end line."""
    meshio.write(path, meshio.Mesh(GRID.points, [("hexahedron", GRID.cells)]), file_format="gmsh22", binary=False)
    with open(path, "a") as f:
        f.write("$Comments\nno end line\n")
    return path


@pytest.fixture
def files(tmp_path):
    out = [M.write_vtu(tmp_path / "good.vtu", GRID), _chatty_gmsh(tmp_path / "chatty.msh")]
    garbage = tmp_path / "garbage.vtu"
    garbage.write_bytes(b"\x00\x01 not a vtu file " * 20)  # meshio prints, then calls sys.exit
    out.append(garbage)
    return out


def test_meshio_words_become_the_warning_not_terminal_output(files, capfd):
    good, chatty, garbage = files
    capfd.readouterr()  # meshio's words while writing the gmsh file
    with pytest.warns(MsslibWarning, match=r"chatty\.msh: meshio says: Warning: \$Comments not closed"):
        mesh = M.read(chatty)
    assert mesh.n_cells == 2
    with pytest.raises(ValueError, match=r"garbage\.vtu: cannot read mesh: .*Couldn't read file") as info:
        M.read(garbage)
    assert "\n" not in str(info.value)
    out, err = capfd.readouterr()
    assert out == "" and err == ""  # file-descriptor level: nothing reached the terminal


@pytest.mark.filterwarnings("ignore:.*meshio says:msslib.errors.MsslibWarning")
def test_eight_threads_reading_leave_the_streams_alone(files, capsys):
    capsys.readouterr()  # meshio's words while writing the gmsh file
    stdout, stderr = sys.stdout, sys.stderr
    results, failures = [], []
    start = threading.Barrier(8)

    def work(k):
        start.wait()
        for _ in range(5):
            path = files[k % 3]
            try:
                results.append((k, M.read(path).n_cells))
            except ValueError as exc:
                failures.append((k, str(exc)))
            print(f"thread {k} printed")  # user code printing while others read

    threads = [threading.Thread(target=work, args=(k,)) for k in range(8)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert sys.stdout is stdout and sys.stderr is stderr
    assert sorted({n for _, n in results}) == [2] and len(results) == 5 * sum(k % 3 != 2 for k in range(8))
    assert len(failures) == 5 * sum(k % 3 == 2 for k in range(8))
    assert all("garbage.vtu: cannot read mesh" in text for _, text in failures)
    print("after the threads")
    out, err = capsys.readouterr()
    lines = out.splitlines()
    assert lines.count("after the threads") == 1
    assert sorted(set(lines) - {"after the threads"}) == [f"thread {k} printed" for k in range(8)]
    assert len(lines) == 8 * 5 + 1  # every print of every thread arrived, none was swallowed
    assert err == ""  # meshio's words (the garbage file makes it print twice) went nowhere


def test_meshio_outside_read_still_speaks(files, capfd):
    """The routing only collects inside msslib's read: meshio called directly prints as before."""
    M.read(files[0])  # installs the routing
    capfd.readouterr()
    with pytest.raises(SystemExit):
        meshio.read(files[2])
    assert "Couldn't read file" in capfd.readouterr().err


def test_read_result_is_the_written_mesh(files):
    mesh = M.read(files[0])
    np.testing.assert_allclose(mesh.points, GRID.points)
    np.testing.assert_array_equal(mesh.cells, GRID.cells)
