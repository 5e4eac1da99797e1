"""Look at the built paper: a screenshot of the HTML in a headless browser, offline, and the pages
of the PDF as PNG images.

    python paper/check_render.py                      # paper/build/paper.{html,typ} -> paper/build/render/
    python paper/check_render.py --html X.html --typst X.typ --out-dir DIR --pages 2

The screenshot needs Chromium or Chrome (``chromium``, ``chromium-browser``, ``google-chrome`` on the
PATH, or the ``CHROME`` environment variable); without one it is skipped with a message. The
browser runs with every network name unresolvable, so the screenshot shows what an offline reader
sees. The pages are rendered by the Typst compiler from the Typst source of the PDF (the same
layout, no PDF viewer needed). Nothing here is part of the build.
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

BROWSERS = ["chromium", "chromium-browser", "google-chrome", "google-chrome-stable"]


def find_browser() -> str | None:
    if os.environ.get("CHROME"):
        return os.environ["CHROME"]
    return next((path for name in BROWSERS if (path := shutil.which(name))), None)


def screenshot(html: Path, png: Path, width: int = 1000, height: int = 2400, browser: str | None = None,
               timeout: float = 120) -> Path:
    """A PNG of the top ``height`` pixels of ``html`` as a headless browser draws it, offline."""
    browser = browser or find_browser()
    if browser is None:
        raise FileNotFoundError("no Chromium or Chrome found (set CHROME to its path)")
    png.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as profile:
        cmd = [browser, "--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
               "--host-resolver-rules=MAP * ~NOTFOUND", "--proxy-server=127.0.0.1:9", "--hide-scrollbars",
               f"--user-data-dir={profile}", f"--window-size={width},{height}",
               f"--screenshot={png.resolve()}", html.resolve().as_uri()]
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
    if not png.is_file():
        raise RuntimeError(f"{browser} made no screenshot ({proc.returncode}):\n{proc.stderr[-2000:]}")
    return png


def pages(typ: Path, out_dir: Path, ppi: float = 80, first: int | None = None) -> list[Path]:
    """The pages of the PDF typeset from ``typ`` as ``out_dir/page-N.png`` (all, or the first
    ``first``)."""
    import re

    import typst

    out_dir.mkdir(parents=True, exist_ok=True)
    images = [(typ.parent / p).resolve() for p in re.findall(r'image\("([^"]+)"', typ.read_text(encoding="utf-8"))]
    root = os.path.commonpath([typ.parent.resolve(), *images])
    for old in out_dir.glob("page-*.png"):
        old.unlink()
    typst.compile(str(typ), output=str(out_dir / "page-{p}.png"), format="png", ppi=ppi, root=root,
                  ignore_system_fonts=True)
    made = sorted(out_dir.glob("page-*.png"), key=lambda p: int(p.stem.split("-")[1]))
    for extra in made[first:] if first else []:
        extra.unlink()
    return made[:first] if first else made


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--html", type=Path, default=Path("paper/build/paper.html"))
    p.add_argument("--typst", type=Path, default=Path("paper/build/paper.typ"), help="Typst source of the PDF")
    p.add_argument("--out-dir", type=Path, default=Path("paper/build/render"))
    p.add_argument("--pages", type=int, default=3, help="how many PDF pages to render (0: all)")
    p.add_argument("--height", type=int, default=2400, help="screenshot height in pixels")
    args = p.parse_args(argv)
    if args.html.is_file():
        try:
            print(screenshot(args.html, args.out_dir / "html.png", height=args.height))
        except FileNotFoundError as exc:
            print(f"HTML screenshot skipped: {exc}", file=sys.stderr)
    else:
        print(f"no HTML at {args.html}", file=sys.stderr)
    if args.typst.is_file():
        for page in pages(args.typst, args.out_dir, first=args.pages or None):
            print(page)
    else:
        print(f"no Typst source at {args.typst}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
