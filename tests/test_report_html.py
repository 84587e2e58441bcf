"""Issue 13.7: each Markdown report has a self-contained HTML twin (figures embedded, provenance stamp),
checked by rendering it in a real headless browser."""

import os
import re
import shutil
import subprocess

import pytest

from _cli import run as run_cli  # in this process: these tests check what the command writes


def _browser():
    for name in ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable"):
        path = shutil.which(name)
        if path:
            return path
    return None


@pytest.fixture(scope="module")
def analysed(tmp_path_factory, ):
    from heavecomp.params import dumps, paper_a

    d = tmp_path_factory.mktemp("html")
    (d / "p.toml").write_text(dumps(paper_a()))
    r = run_cli("analyse", str(d / "p.toml"), "--out", str(d / "out"),
                "--points", "60", "-q")
    assert r.returncode == 0, r.stderr
    return d / "out"


def test_html_is_self_contained_and_stamped(analysed):
    md = (analysed / "report.md").read_text()
    page = (analysed / "report.html").read_text()
    n_fig = len(re.findall(r"!\[[^\]]*\]\([^)]+\.png\)", md))
    assert n_fig >= 1
    srcs = re.findall(r'<img[^>]*src="([^"]+)"', page)
    assert len(srcs) == n_fig and all(s.startswith("data:image/png;base64,") for s in srcs)
    assert "<table>" in page and "Provenance:" in page and "heavecomp analyse" in page
    assert md.rstrip().splitlines()[-1].startswith("*Provenance: heavecomp ")


def test_missing_figure_is_named_not_dropped(tmp_path):
    from heavecomp.report.html import markdown_to_html

    page = markdown_to_html("# T\n\n![x](gone.png)\n", tmp_path)
    assert "figure gone.png missing" in page


_CHECK = """<script>
window.addEventListener('load', function () {
  var imgs = Array.prototype.slice.call(document.images);
  var ok = imgs.filter(function (i) { return i.complete && i.naturalWidth > 100; }).length;
  var d = document.createElement('div'); d.id = 'heavecomp-check';
  d.textContent = 'IMAGES ' + ok + '/' + imgs.length + ' TABLES ' + document.querySelectorAll('table').length
    + ' HEIGHT ' + document.body.scrollHeight;
  document.body.appendChild(d);
});
</script></body>"""


def test_html_renders_in_a_headless_browser(analysed, tmp_path):
    browser = _browser()
    if browser is None:
        pytest.skip("no headless browser (chromium) installed: `apt-get install chromium` to run this check")
    # alone in an empty folder: the page must not need the PNGs beside it
    page = (analysed / "report.html").read_text().replace("</body>", _CHECK, 1)
    (tmp_path / "alone.html").write_text(page)
    env = dict(os.environ, HOME=str(tmp_path))
    r = subprocess.run([browser, "--headless", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
                        "--virtual-time-budget=5000", "--dump-dom", (tmp_path / "alone.html").as_uri()],
                       capture_output=True, text=True, timeout=120, env=env)
    m = re.search(r"IMAGES (\d+)/(\d+) TABLES (\d+) HEIGHT (\d+)", r.stdout)
    assert m, (r.returncode, r.stderr[-2000:])
    ok, n, tables, height = map(int, m.groups())
    assert n >= 1 and ok == n, f"{n - ok} of {n} figures did not decode in the browser"
    assert tables >= 1 and height > 800
