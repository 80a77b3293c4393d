"""report.html opens in a browser: headless Chromium (Debian's ``chromium``) loads the page of
a real campaign (tests/data/real18_k1.h5) and every embedded figure decodes to an image.
Skipped where chromium is not installed (.ci/run installs it)."""

import os
import re
import shutil
import subprocess

import pytest

from fibril_hpc.campaign.analysis.report import write_report

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
FIXTURE = os.path.join(os.path.dirname(__file__), "data", "real18_k1.h5")
# the test's own probe, appended to a copy of the page: counts the images the browser decoded
PROBE = """<script>window.addEventListener('load', () => {
  const imgs = Array.from(document.images);
  const ok = imgs.filter(i => i.complete && i.naturalWidth > 100 && i.naturalHeight > 100);
  const d = document.createElement('div'); d.id = 'figcheck';
  d.textContent = ok.length + '/' + imgs.length; document.body.appendChild(d);
});</script>"""


@pytest.mark.skipif(CHROMIUM is None, reason="chromium is not installed (apt-get install chromium)")
def test_every_figure_of_report_html_renders_in_chromium(tmp_path):
    out = tmp_path / "rep"
    files = write_report(FIXTURE, str(out), n_boot=20)
    pngs = [f for f in files if f.endswith(".png")]
    page = (out / "report.html").read_text()
    assert "<img" in page and "src='data:image/png;base64," in page
    assert not re.search(r"<img[^>]+src='(?!data:)", page)        # self-contained: no file links
    probe = tmp_path / "probe.html"
    probe.write_text(page.replace("</body>", PROBE + "</body>"))
    r = subprocess.run([CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu",
                        "--disable-dev-shm-usage", "--virtual-time-budget=15000", "--dump-dom",
                        probe.as_uri()], capture_output=True, text=True, timeout=180,
                       env=dict(os.environ, HOME=str(tmp_path)))
    m = re.search(r'<div id="figcheck">(\d+)/(\d+)</div>', r.stdout)
    assert m, (r.returncode, r.stderr[-2000:])
    assert int(m.group(1)) == int(m.group(2)) == len(pngs) >= 6
