"""Self-contained HTML beside each Markdown report: figures embedded as base64, the provenance stamp kept.

``report.html`` needs no other file: it can be mailed or archived on its own.  The Markdown is
converted by Python-Markdown (tables, fenced code); every local image ``![..](fig.png)`` becomes a
``data:`` URI.  A figure that is missing is named in the page (and logged), never silently dropped.
"""

from __future__ import annotations

import base64
import html
import logging
import re
from pathlib import Path

log = logging.getLogger(__name__)

_STYLE = """
body { font-family: system-ui, -apple-system, "Segoe UI", sans-serif; max-width: 1100px; margin: 2em auto;
       padding: 0 1em; line-height: 1.45; color: #222; }
table { border-collapse: collapse; margin: 1em 0; font-size: 0.92em; }
th, td { border: 1px solid #bbb; padding: 0.25em 0.6em; text-align: right; }
th { background: #eee; } td:first-child, th:first-child { text-align: left; }
img { max-width: 100%; height: auto; display: block; margin: 1em 0; }
code { background: #f4f4f4; padding: 0 0.2em; } pre { background: #f4f4f4; padding: 0.6em; overflow-x: auto; }
.provenance { color: #555; font-size: 0.9em; border-top: 1px solid #ccc; margin-top: 2em; padding-top: 0.5em; }
.missing { color: #b00; }
"""

_MIME = {".png": "image/png", ".jpg": "image/jpeg", ".jpeg": "image/jpeg", ".svg": "image/svg+xml",
         ".gif": "image/gif"}


def _embed_images(body: str, folder: Path) -> str:
    def repl(m):
        src = html.unescape(m.group(2))
        if re.match(r"^(data:|https?:)", src):
            return m.group(0)
        path = folder / src
        mime = _MIME.get(path.suffix.lower())
        if mime is None or not path.is_file():
            log.warning("report.html: figure %s not found beside the report", src)
            return f'<p class="missing">[figure {html.escape(src)} missing]</p>'
        data = base64.b64encode(path.read_bytes()).decode("ascii")
        return f'{m.group(1)}data:{mime};base64,{data}{m.group(3)}'

    return re.sub(r'(<img[^>]*?src=")([^"]+)("[^>]*>)', repl, body)


def markdown_to_html(text: str, folder, *, title: str | None = None) -> str:
    """A complete HTML page for the Markdown ``text`` whose figures live in ``folder``.

    Parameters
    ----------
    text : str
        The Markdown.
    folder : str or os.PathLike
        Folder the relative image paths of ``text`` are resolved from (the images are embedded).
    title : str or None
        The page title (None: the first ``#`` heading, else ``heavecomp report``).

    Returns
    -------
    str
    """
    import markdown  # lazy: only report writing needs it

    body = markdown.markdown(text, extensions=["tables", "fenced_code", "sane_lists"], output_format="html")
    body = _embed_images(body, Path(folder))
    body = re.sub(r"<p><em>(Provenance:.*?)</em></p>", r'<p class="provenance"><em>\1</em></p>', body, flags=re.S)
    if title is None:
        m = re.search(r"^#\s+(.+)$", text, flags=re.M)
        title = m.group(1).strip() if m else "heavecomp report"
    return (f'<!DOCTYPE html>\n<html lang="en">\n<head>\n<meta charset="utf-8">\n'
            f"<title>{html.escape(title)}</title>\n<style>{_STYLE}</style>\n</head>\n<body>\n{body}\n</body>\n</html>\n")


def write_html(md_path) -> Path:
    """Write ``report.html`` beside ``report.md`` (same stem).

    Parameters
    ----------
    md_path : str or os.PathLike
        The Markdown report (UTF-8); its figures are resolved from its folder.

    Returns
    -------
    pathlib.Path
        The HTML file written.
    """
    md_path = Path(md_path)
    out = md_path.with_suffix(".html")
    out.write_text(markdown_to_html(md_path.read_text(encoding="utf-8"), md_path.parent), encoding="utf-8")
    return out
