"""Tables for the terminal and self-contained HTML pages (figures as PNG files beside them)."""

from __future__ import annotations

import html
import re
import shutil
import tempfile
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path

PAGE_FILE = "index.html"
"""A report folder's page; its figures are files beside it."""


def text_table(header: Sequence[str], rows: Sequence[Sequence[str]]) -> str:
    """A fixed-width table for the terminal."""
    widths = [max(len(str(x)) for x in col) for col in zip(header, *rows, strict=True)]
    lines = ["  ".join(str(h).ljust(w) for h, w in zip(header, widths, strict=True))]
    lines += ["  ".join(str(x).ljust(w) for x, w in zip(row, widths, strict=True))
              for row in rows]
    return "\n".join(lines)


def write_html(path: Path, title: str, sections: Sequence[tuple[str, str]],
               first_screen: int | None = None) -> Path:
    """One self-contained page (figures next to it); ``sections`` are (heading, html body).
    With ``first_screen``, the sections after that many are folded, each opened from a link
    at the top: the page had run past 16,000 px, its verdict a screen of many."""
    shown = len(sections) if first_screen is None else first_screen
    links = " · ".join(f"<a href='#{_anchor(h)}'>{html.escape(h)}</a>"
                       for h, _ in sections[shown:])
    body = "\n".join(
        f"<h2 id='{_anchor(h)}'>{html.escape(h)}</h2>\n{b}" if i < shown else
        f"<details id='{_anchor(h)}'><summary><h2>{html.escape(h)}</h2></summary>\n{b}"
        "</details>" for i, (h, b) in enumerate(sections))
    page = (f"<!doctype html><html><head><meta charset='utf-8'><title>{html.escape(title)}"
            "</title><style>body{font-family:sans-serif;max-width:1100px;margin:auto}"
            "table{border-collapse:collapse}td,th{border:1px solid #ccc;padding:3px 8px;"
            "font-size:13px}img{max-width:100%}summary h2{display:inline;cursor:pointer}"
            "details{margin:0.8em 0}</style><script>addEventListener('hashchange',()=>{"
            "const d=document.getElementById(location.hash.slice(1));if(d)d.open=true})"
            f"</script></head><body><h1>{html.escape(title)}</h1>\n"
            + (f"<p>Further down: {links}</p>\n" if links else "")
            + f"{body}</body></html>")
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(page)
    return path


def write_report(folder: Path, title: str,
                 sections: Callable[[Path], Sequence[tuple[str, str]]],
                 first_screen: int | None = None) -> Path:
    """A report page ``folder/index.html`` (:func:`write_html`) with the figures that
    ``sections`` draws into the folder it is given, all or nothing (:func:`staged`);
    returns the page."""
    with staged(folder) as stage:
        write_html(stage / PAGE_FILE, title, sections(stage), first_screen)
    return Path(folder) / PAGE_FILE


@contextmanager
def staged(folder: Path) -> Iterator[Path]:
    """A folder to write a report into; once all is written, its files are moved into
    ``folder``, the page last. A report stopped midway (Ctrl-C, SIGTERM, an error) had left
    the page before it beside the new figures drawn so far, which it showed as its own:
    now that report stays as it was, and nothing of the new one is left. The stage is a
    hidden folder inside ``folder``, on its file system: each move is a rename. Then the
    figures the page before it showed and this one does not are removed (:func:`shown`):
    a folder used again had kept the figures of runs its campaign no longer had."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    before = shown(folder / PAGE_FILE)
    stage = Path(tempfile.mkdtemp(prefix=".writing-", dir=folder))
    try:
        yield stage
        written = sorted((path.relative_to(stage) for path in stage.rglob("*")
                          if path.is_file()), key=lambda name: name == Path(PAGE_FILE))
        for name in written:
            (folder / name).parent.mkdir(parents=True, exist_ok=True)
            (stage / name).replace(folder / name)
        for name in before - set(written):
            if (folder / name).is_file():
                (folder / name).unlink()
    finally:
        shutil.rmtree(stage, ignore_errors=True)


def shown(page: Path) -> set[Path]:
    """The figures ``page`` shows (:func:`html_image`), as paths in its folder; only those
    inside it (a page is ours, but its folder may hold anything)."""
    try:
        text = page.read_text(errors="replace")
    except OSError:  # no page yet
        return set()
    folder = page.parent.resolve()
    names = {Path(html.unescape(src)) for src in re.findall(r"<img src='([^']*)'>", text)}
    return {name for name in names if not name.is_absolute()
            and (folder / name).resolve().is_relative_to(folder)}


def _anchor(heading: str) -> str:
    return "-".join("".join(c if c.isalnum() else " " for c in heading.lower()).split())


def html_table(header: Sequence[str], rows: Sequence[Sequence[str]]) -> str:
    head = "".join(f"<th>{html.escape(str(h))}</th>" for h in header)
    body = "".join("<tr>" + "".join(f"<td>{html.escape(str(x))}</td>" for x in row) + "</tr>"
                   for row in rows)
    return f"<table><tr>{head}</tr>{body}</table>"


def html_image(path: Path, relative_to: Path) -> str:
    return f"<img src='{html.escape(str(Path(path).relative_to(relative_to)))}'>"
