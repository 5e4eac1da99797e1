"""Table 1 of the paper (paper/sections/status.md): one row per item of the three papers, six
columns, and a status that the build computes in every row (a ``{{claim ...}}``, which fails the
build when the numbers contradict it), never a typed one."""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
# experiments, figures, tables and formulas of the three papers that the paper repeats: the referee's 43,
# Lloyd's Fig. 16 errors (printed in Sec. 5.6) and Baudet's 5 % bound on the E error (Sec. 5), one row each
ITEMS = 45


def _cells(line: str) -> list[str]:
    """The cells of a Markdown table row; bars inside ``{{...}}`` markers do not split."""
    cells, depth, cur, i = [], 0, "", 0
    while i < len(line):
        if line.startswith("{{", i):
            depth, cur, i = depth + 1, cur + "{{", i + 2
        elif line.startswith("}}", i):
            depth, cur, i = depth - 1, cur + "}}", i + 2
        elif line[i] == "|" and depth == 0:
            cells.append(cur)
            cur, i = "", i + 1
        else:
            cur, i = cur + line[i], i + 1
    cells.append(cur)
    return [c.strip() for c in cells[1:-1]]


def _rows():
    text = (ROOT / "paper" / "sections" / "status.md").read_text(encoding="utf-8")
    table = text[text.index("**Table 1."):]
    return [_cells(line) for line in table.splitlines()[1:]
            if line.startswith("| ") and not line.startswith("| paper, item")]


def test_one_row_per_item_with_six_columns():
    rows = _rows()
    assert len(rows) >= ITEMS, len(rows)
    assert all(len(r) == 6 for r in rows), [r[0] for r in rows if len(r) != 6]
    names = [r[0] for r in rows]
    assert len(set(names)) == len(names), "two rows name the same item"
    # the three papers' items, then the element types this project adds from later papers
    assert all(re.match(r"(Lloyd|Baudet|Golec|Kikuuwe), ", n) for n in names), names


def test_every_status_is_computed_by_the_build():
    typed = [r[0] for r in _rows() if not r[4].startswith("{{claim ") or not r[4].endswith("}}")]
    assert not typed, typed


STATUSES = ("reproduced", "partly", "not", "missing")


def _claim_text(cell: str) -> str:
    """The sentence a ``{{claim CONDITION | TEXT}}`` prints: what follows the first bar at depth one."""
    depth = 0
    for i in range(len(cell)):
        if cell.startswith("{{", i):
            depth += 1
        elif cell.startswith("}}", i):
            depth -= 1
        elif cell[i] == "|" and depth == 1:
            return cell[i + 1:-2].strip()
    raise AssertionError(f"no text in {cell[:60]}")


def test_one_status_per_row():
    """Each status opens with one of the four statuses and names no second one (a row that gave one
    status per reading would be two items in one row)."""
    for name, *_, status, _ in _rows():
        text = _claim_text(status)
        first = re.match(r"[a-z]+", text)
        assert first and first.group(0) in STATUSES, (name, text[:40])
        for word in STATUSES:
            assert not re.search(rf"reading: {word}\b", text), (name, text[:80])


def test_claim_text_is_found():
    assert _claim_text("{{claim [a] < 1 | partly: {{value a fmt=.1f}} x}}") == "partly: {{value a fmt=.1f}} x"
    assert _claim_text("{{claim max([a], [b]) < 1 | not}}") == "not"
