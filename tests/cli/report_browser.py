#!/usr/bin/env python3
"""Opens a `drift report` page in headless Chromium and checks it (tests/cli/test_report.sh).

Chromium is driven over the DevTools protocol on a pipe (--remote-debugging-pipe: JSON
messages ending in NUL on file descriptors 3 and 4), with the standard library only. Checks:
the page loads with no console error or exception and no request other than file: and data:
URLs; every image it references exists and every image it shows decodes; the comparison
slider follows a synthetic pointer; each plot holds one mark per table row with numbers; a
screenshot is not blank; each row's numbers equal `drift diff --json` on the same files (the
sir cell's rows against its whole-frame truth too).

usage: report_browser.py DRIFT DIR [--expect-error TEXT]... [--screenshot FILE.png]
                         [--no-numbers] [--sir-marks N] [DIR ...]
(each DIR a report folder, checked in one browser; --expect-error: a cell of that page must
hold TEXT, and without it no cell may report an error; --no-numbers: skip the drift diff runs;
--sir-marks N: the page's sir plot holds N SIR marks joined as one curve)
exit status 0 when every check passes, 1 otherwise (each failure printed as FAIL: ...).
"""
import base64
import json
import os
import shutil
import struct
import subprocess
import sys
import tempfile
import time
import zlib

failures = []


def fail(message):
    print("FAIL: " + message, file=sys.stderr)
    failures.append(message)


class Browser:
    """Chromium with the DevTools protocol on a pipe; one page target, flattened session."""

    def __init__(self, binary):
        self.profile = tempfile.mkdtemp(prefix="drift-report-chromium-")
        to_child_r, self.to_child = os.pipe()
        self.from_child, from_child_w = os.pipe()

        def child_fds():
            # Moved out of the way first: a pipe end may already be 3 or 4, and dup2 onto
            # itself would leave it close-on-exec.
            read_end, write_end = os.dup(to_child_r), os.dup(from_child_w)
            os.dup2(read_end, 3)
            os.dup2(write_end, 4)

        args = [binary, "--headless=new", "--remote-debugging-pipe", "--no-sandbox",
                "--disable-gpu", "--disable-dev-shm-usage", "--no-first-run",
                "--no-default-browser-check", "--disable-extensions", "--disable-background-networking",
                "--disable-component-update", "--disable-sync", "--mute-audio",
                "--user-data-dir=" + self.profile, "about:blank"]
        log = None if os.environ.get("DRIFT_REPORT_BROWSER_LOG") else subprocess.DEVNULL
        self.process = subprocess.Popen(args, close_fds=False,
                                        preexec_fn=child_fds, stdout=subprocess.DEVNULL, stderr=log)
        os.close(to_child_r)
        os.close(from_child_w)
        self.buffer = b""
        self.next_id = 0
        self.events = []
        self.session = None

    def _read_message(self, deadline):
        while b"\0" not in self.buffer:
            if time.time() > deadline:
                raise TimeoutError("no answer from chromium")
            chunk = os.read(self.from_child, 1 << 20)
            if not chunk:
                raise EOFError("chromium closed the pipe")
            self.buffer += chunk
        message, self.buffer = self.buffer.split(b"\0", 1)
        return json.loads(message)

    def send(self, method, params=None, session=True, timeout=60):
        self.next_id += 1
        message = {"id": self.next_id, "method": method, "params": params or {}}
        if session and self.session:
            message["sessionId"] = self.session
        os.write(self.to_child, json.dumps(message).encode() + b"\0")
        deadline = time.time() + timeout
        while True:
            reply = self._read_message(deadline)
            if reply.get("id") == self.next_id:
                if "error" in reply:
                    raise RuntimeError("%s: %s" % (method, reply["error"]))
                return reply.get("result", {})
            self.events.append(reply)

    def wait_event(self, method, timeout=60):
        for event in self.events:
            if event.get("method") == method:
                return event
        deadline = time.time() + timeout
        while True:
            event = self._read_message(deadline)
            self.events.append(event)
            if event.get("method") == method:
                return event

    def evaluate(self, expression):
        result = self.send("Runtime.evaluate", {"expression": expression, "returnByValue": True,
                                                "awaitPromise": True})
        if "exceptionDetails" in result:
            raise RuntimeError("page script failed: %s" % result["exceptionDetails"])
        return result["result"].get("value")

    def close(self):
        try:
            self.send("Browser.close", session=False, timeout=10)
        except Exception:
            pass
        try:
            self.process.wait(timeout=5)
        except subprocess.TimeoutExpired:
            self.process.kill()
        shutil.rmtree(self.profile, ignore_errors=True)


def png_pixels(data):
    """(width, height, rows of RGB(A) bytes) of an 8-bit RGB or RGBA PNG."""
    assert data[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
    pos, idat, width = 8, b"", 0
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            width, height, depth, colour = struct.unpack(">IIBB", body[:10])
            assert depth == 8 and colour in (2, 6), "unexpected PNG format"
            channels = 3 if colour == 2 else 4
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    raw = zlib.decompress(idat)
    stride = width * channels
    rows, previous = [], bytearray(stride)
    for y in range(height):
        kind = raw[y * (stride + 1)]
        line = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - channels] if i >= channels else 0
            b = previous[i]
            c = previous[i - channels] if i >= channels else 0
            if kind == 1:
                line[i] = (line[i] + a) & 255
            elif kind == 2:
                line[i] = (line[i] + b) & 255
            elif kind == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif kind == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(bytes(line))
        previous = line
    return width, height, channels, rows


def check_screenshot(browser, path):
    shot = browser.send("Page.captureScreenshot", {"format": "png", "clip": {
        "x": 0, "y": 0, "width": 1000, "height": 800, "scale": 0.5}})
    data = base64.b64decode(shot["data"])
    if path:
        with open(path, "wb") as f:
            f.write(data)
    width, height, channels, rows = png_pixels(data)
    colours = set()
    background = rows[0][:3]
    other = 0
    for row in rows:
        for x in range(0, width * channels, channels):
            pixel = row[x:x + 3]
            colours.add(pixel)
            other += pixel != background
    if len(colours) < 64 or other < width * height // 20:
        fail("the screenshot looks blank: %d colours, %d of %d pixels off the background"
             % (len(colours), other, width * height))


def check_numbers(drift, folder, rows):
    """Each row's FLIP, RMSE and SSIM (the cell's data-value and its text) against drift diff."""
    checked = 0
    for row in rows:
        if not row["image"]:
            continue
        out = subprocess.run([drift, "diff", "--json",
                              os.path.join(folder, row["reference"] + ".exr"),
                              os.path.join(folder, row["image"] + ".exr")],
                             capture_output=True, text=True)
        if out.returncode != 0:
            fail("drift diff failed on %s: %s" % (row["image"], out.stderr.strip()))
            continue
        diff = json.loads(out.stdout)
        for key in ("flip", "rmse", "ssim"):
            text, value = row["cells"][key]
            if value is None or float(value) != diff[key]:
                fail("%s %s: the page's %s is %s, drift diff says %r"
                     % (row["effect"], row["label"], key, value, diff[key]))
            elif abs(float(text) - diff[key]) > 5e-4 * max(abs(diff[key]), 1e-12):
                fail("%s %s: the page shows %s = %s, drift diff says %r"
                     % (row["effect"], row["label"], key, text, diff[key]))
        checked += 1
    return checked


PAGE_ROWS = """
[...document.querySelectorAll("section.effect")].flatMap(section => {
  const effect = section.dataset.effect;
  const scene = section.closest("section.scene");
  const data = window.driftReport.data.scenes.find(s => s.path === scene.dataset.scene)
    .effects.find(e => e.effect === effect);
  return [...section.querySelectorAll("table.metrics tbody tr")].map(tr => {
    const row = data.rows[+tr.dataset.row];
    const cells = {};
    tr.querySelectorAll("td").forEach(td => cells[td.dataset.key] = [td.textContent, td.dataset.value === undefined ? null : td.dataset.value]);
    return { effect: effect, label: cells.label[0], image: row.image || null,
             reference: data.reference.image, cells: cells };
  });
})
"""

PLOT_MARKS = """
[...document.querySelectorAll("section.effect")].filter(s => s.querySelector("table.metrics")).map(s => ({
  effect: s.dataset.effect,
  marks: [...s.querySelectorAll("svg.plot circle.mark")].map(c => +c.dataset.row).sort((a, b) => a - b),
  rows: [...s.querySelectorAll("table.metrics tbody tr")].filter(tr => tr.querySelector("td[data-key=flip]").dataset.value !== undefined).map(tr => +tr.dataset.row).sort((a, b) => a - b),
  pareto: s.querySelectorAll("svg.plot circle.mark.pareto").length,
  sir: [...s.querySelectorAll("svg.plot circle.mark")].filter(c => window.driftReport.data.scenes
    .find(x => x.path === s.closest("section.scene").dataset.scene).effects
    .find(e => e.effect === s.dataset.effect).rows[+c.dataset.row].technique === "sir").length,
  curves: [...s.querySelectorAll("svg.plot polyline.sweep")].map(p => p.getAttribute("points").trim().split(/\s+/).length)
}))
"""

SHOWN_IMAGES = """
Promise.all([...document.images].map(img => img.decode().then(() => [img.getAttribute("src"), img.naturalWidth], () => [img.getAttribute("src"), 0])))
"""


def check_slider(browser):
    box = browser.evaluate("""(() => { const b = document.querySelector(".compare");
        if (!b) return null; b.scrollIntoView({block: "center"});
        const r = b.getBoundingClientRect();
        return {x: r.left, y: r.top, w: r.width, h: r.height, split: +b.dataset.split}; })()""")
    if not box:
        fail("the page has no comparison slider")
        return
    y = box["y"] + box["h"] / 2
    for fraction, kind, buttons in ((0.25, "mousePressed", 1), (0.8, "mouseMoved", 1),
                                    (0.8, "mouseReleased", 0)):
        browser.send("Input.dispatchMouseEvent", {
            "type": kind, "x": box["x"] + fraction * box["w"], "y": y, "button": "left",
            "buttons": buttons, "clickCount": 1})
        split = browser.evaluate("+document.querySelector('.compare').dataset.split")
        if abs(split - fraction) > 0.02:
            fail("the slider is at %.3f after a pointer %s at %.2f" % (split, kind, fraction))
    clip = browser.evaluate("document.querySelector('.compare .top').style.clipPath")
    if "20%" not in clip:
        fail("the technique image is not clipped at the split: clip-path %r" % clip)


def check_page(browser, drift, folder, expect_errors, screenshot, numbers, sir_marks):
    browser.events.clear()
    browser.send("Page.navigate", {"url": "file://" + folder + "/index.html"})
    browser.wait_event("Page.loadEventFired")
    if browser.evaluate("document.body.dataset.ready") != "1":
        thrown = [e["params"]["exceptionDetails"] for e in browser.events
                  if e.get("method") == "Runtime.exceptionThrown"]
        fail("the page's script did not finish building the page: %s"
             % [t.get("exception", {}).get("description", t.get("text")) for t in thrown])
        return

    referenced = browser.evaluate("window.driftReport.images()")
    missing = [p for p in referenced if not os.path.isfile(os.path.join(folder, p))]
    if not referenced or missing:
        fail("%d images referenced, missing: %s" % (len(referenced), missing[:5]))
    for src, width in browser.evaluate(SHOWN_IMAGES):
        if width == 0:
            fail("the image %s does not load" % src)

    check_slider(browser)
    plots = browser.evaluate(PLOT_MARKS)
    if sir_marks is not None:
        sir = [p for p in plots if p["effect"] == "sir"]
        if not sir or sir[0]["sir"] != sir_marks:
            fail("the sir plot holds %s SIR marks, expected %d (the raster frame and each"
                 " iteration count)" % (sir[0]["sir"] if sir else "no", sir_marks))
        elif sir_marks > 1 and sir_marks not in sir[0]["curves"]:
            fail("the SIR marks are not joined as one curve: polylines of %s points"
                 % sir[0]["curves"])
    for plot in plots:
        if not plot["rows"] or plot["marks"] != plot["rows"]:
            fail("%s: the plot's marks %s are not the table's rows %s"
                 % (plot["effect"], plot["marks"], plot["rows"]))
        if plot["pareto"] < 1:
            fail("%s: no mark on the Pareto front" % plot["effect"])

    # Sorting by FLIP puts the rows in FLIP order.
    order = browser.evaluate("""(() => { const s = document.querySelector("section.effect table.metrics");
        if (!s) return []; s.querySelector("th[data-key=flip]").click();
        return [...s.querySelectorAll("tbody td[data-key=flip]")].map(td => td.dataset.value === undefined ? null : +td.dataset.value); })()""")
    finite = [v for v in order if v is not None]
    if not finite or finite != sorted(finite):
        fail("sorting by FLIP gives %s" % order)

    errors_on_page = browser.evaluate(
        "[...document.querySelectorAll('.cell-error')].map(e => e.textContent)")
    for text in expect_errors:
        if not any(text in e for e in errors_on_page):
            fail("no cell says %r (cells: %s)" % (text, errors_on_page))
    if not expect_errors and errors_on_page:
        fail("cells report errors: %s" % errors_on_page)

    checked = check_numbers(drift, folder, browser.evaluate(PAGE_ROWS)) if numbers else 0
    if numbers and checked == 0:
        fail("no row of the page could be checked against drift diff")
    check_screenshot(browser, screenshot)

    requests = [e["params"]["request"]["url"] for e in browser.events
                if e.get("method") == "Network.requestWillBeSent"]
    if not requests:
        fail("chromium saw no request at all (the network log is not working)")
    for url in requests:
        if not (url.startswith("file:") or url.startswith("data:")):
            fail("the page made a network request: %s" % url)
    for e in browser.events:
        method, params = e.get("method"), e.get("params", {})
        if method == "Runtime.exceptionThrown":
            fail("exception in the page: %s" % params["exceptionDetails"].get("text"))
        elif method == "Runtime.consoleAPICalled" and params.get("type") in ("error", "assert"):
            fail("console error: %s" % [a.get("value") for a in params.get("args", [])])
        elif method == "Log.entryAdded" and params["entry"]["level"] == "error":
            fail("console error: %s" % params["entry"].get("text"))
    print("report_browser: %s: %d images, %d rows checked against drift diff, %d requests"
          % (folder, len(referenced), checked, len(requests)))


def main():
    args = sys.argv[1:]
    drift, pages = args[0], []
    i = 1
    while i < len(args):
        if args[i] == "--expect-error":
            pages[-1][1].append(args[i + 1])
            i += 2
        elif args[i] == "--screenshot":
            pages[-1][2] = args[i + 1]
            i += 2
        elif args[i] == "--no-numbers":
            pages[-1][3] = False
            i += 1
        elif args[i] == "--sir-marks":
            pages[-1][4] = int(args[i + 1])
            i += 2
        else:
            pages.append([os.path.abspath(args[i]), [], None, True, None])
            i += 1
    binary = shutil.which("chromium") or shutil.which("chromium-browser")
    browser = Browser(binary)
    try:
        target = browser.send("Target.createTarget", {"url": "about:blank"}, session=False)
        browser.session = browser.send("Target.attachToTarget", {
            "targetId": target["targetId"], "flatten": True}, session=False)["sessionId"]
        for domain in ("Page", "Runtime", "Log", "Network"):
            browser.send(domain + ".enable")
        browser.send("Emulation.setDeviceMetricsOverride", {
            "width": 1200, "height": 900, "deviceScaleFactor": 1, "mobile": False})
        for folder, expect_errors, screenshot, numbers, sir_marks in pages:
            check_page(browser, drift, folder, expect_errors, screenshot, numbers, sir_marks)
    finally:
        browser.close()
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
