#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Opens tgraph's HTML report in headless Chromium (no network) and checks it.

Fails when the page reports a JavaScript error (uncaught exception, console.error, a chart
that failed to render) or Chromium logs one, when a chart container holds no non-empty SVG
or canvas, or when fewer charts rendered than the page declared. Checks the lost time's
stacked bars and the critical path outlined on the timeline and drawn on the step graph, the step graph's
first view (every node inside the box) and its pan and zoom (a copy of the page with a probe
script wheels, clicks the zoom buttons and records the SVG's transform each time) and the quotient graph (K processor nodes p0..pK-1,
K from the page's title, with loads that add up to the step's tasks and to 100 %, and
edges labelled with bytes and signals). Saves a PNG screenshot.

  browser_check.py --tgraph build/release/apps/tgraph --chromium /usr/bin/chromium \
      --screenshot report.png            # runs `tgraph demo` and checks its report
  browser_check.py --report r.html ...   # checks an existing page
"""
import argparse
import html.parser
import json
import os
import re
import subprocess
import sys
import tempfile

BUDGET_MS = "20000"  # virtual time for the scripts to run before the DOM is taken


class ChartScan(html.parser.HTMLParser):
    """Collects, per element whose class contains "chart" (or "graph"), whether it holds a
    non-empty <svg> (one with children) or a <canvas>."""

    VOID = {"meta", "link", "br", "img", "input", "hr", "col", "source", "wbr", "area", "base", "embed",
            "param", "track"}

    def __init__(self):
        super().__init__()
        self.stack = []  # (tag, chart id or None)
        self.charts = {}  # id -> {"drawn": bool, "error": bool}
        self.svg_depth = []  # for each open <svg>, number of children seen
        self.body_attrs = {}
        self.root_attrs = {}

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if tag == "html":
            self.root_attrs = a
        if tag == "body":
            self.body_attrs = a
        classes = (a.get("class") or "").split()
        chart = None
        if "chart" in classes or "graph" in classes:
            chart = a.get("id") or "graph-%d" % len(self.charts)
            self.charts[chart] = {"drawn": False, "error": "chart-error" in classes}
        open_charts = [c for _, c in self.stack if c]
        if self.svg_depth:
            self.svg_depth[-1] += 1
            if open_charts:
                self.charts[open_charts[-1]]["drawn"] = True
        if tag == "canvas" and open_charts:
            self.charts[open_charts[-1]]["drawn"] = True
        if tag == "svg":
            self.svg_depth.append(0)
        if tag not in self.VOID:
            self.stack.append((tag, chart))

    def handle_startendtag(self, tag, attrs):
        self.handle_starttag(tag, attrs)
        if tag not in self.VOID:
            self.handle_endtag(tag)

    def handle_endtag(self, tag):
        if tag == "svg" and self.svg_depth:
            self.svg_depth.pop()
        for i in range(len(self.stack) - 1, -1, -1):
            if self.stack[i][0] == tag:
                del self.stack[i:]
                break


class GraphScan(html.parser.HTMLParser):
    """Collects the Graphviz nodes and edges inside the element with id `container`: for each
    <g class="node"> or <g class="edge">, its <title> and the texts of its <text> elements."""

    def __init__(self, container):
        super().__init__()
        self.container = container
        self.depth = 0  # open elements inside the container (0: outside)
        self.items = []  # {"class": "node"|"edge", "title": str, "texts": [str]}
        self.current = None
        self.current_depth = 0
        self.field = None

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if self.depth == 0:
            if a.get("id") == self.container:
                self.depth = 1
            return
        self.depth += 1
        if tag == "g" and a.get("class") in ("node", "edge") and self.current is None:
            self.current = {"class": a["class"], "title": "", "texts": []}
            self.current_depth = self.depth
            self.items.append(self.current)
        elif self.current is not None and tag in ("title", "text"):
            self.field = tag
            if tag == "text":
                self.current["texts"].append("")

    def handle_endtag(self, tag):
        if self.depth == 0:
            return
        if self.current is not None and self.depth == self.current_depth:
            self.current = None
        self.field = None
        self.depth -= 1

    def handle_data(self, data):
        if self.current is None or self.field is None:
            return
        if self.field == "title":
            self.current["title"] += data
        else:
            self.current["texts"][-1] += data


# Appended to a copy of the page: after the charts ran, records whether the first view holds
# every node of the step graph inside the box, then zooms with the wheel and the buttons
# (+, whole graph) and records the SVG's CSS transform after each on <html data-probe>.
PROBE = """<script>
(function () {
  var box = document.getElementById('graph-step');
  var svg = box ? box.querySelector('svg') : null;
  var p = {ready: box ? (box.dataset.panzoom || '') : 'no #graph-step',
           inside: !!svg && svg.parentElement === box};
  function done() { document.documentElement.dataset.probe = JSON.stringify(p); }
  // Headless Chromium under --virtual-time-budget runs animation frames only at load (two
  // frames, then none): Panzoom applies each transform in a frame callback, so frames are
  // driven by timers here, the library's code unchanged.
  window.requestAnimationFrame = function (cb) {
    return setTimeout(function () { cb(performance.now()); }, 16);
  };
  if (!svg) { done(); return; }
  var r = box.getBoundingClientRect();
  // Panzoom applies a transform on the next animation frame: each action waits 200 ms.
  // Nodes whose box is not inside the pan/zoom box (1 px of rounding allowed).
  function outside() {
    var b = box.getBoundingClientRect(), out = [];
    svg.querySelectorAll('g.node').forEach(function (n) {
      var q = n.getBoundingClientRect();
      if (q.left < b.left - 1 || q.top < b.top - 1 || q.right > b.right + 1 ||
          q.bottom > b.bottom + 1) {
        var t = n.querySelector('title');
        out.push(t ? t.textContent : '?');
      }
    });
    return out;
  }
  var steps = [
    function () {
      p.start = svg.style.transform;
      p.nodes = svg.querySelectorAll('g.node').length;
      p.start_outside = outside();
    },
    function () {
      box.dispatchEvent(new WheelEvent('wheel', {deltaY: -400, clientX: r.left + r.width / 3,
          clientY: r.top + r.height / 3, bubbles: true, cancelable: true}));
    },
    function () { p.wheel = svg.style.transform; document.querySelector('[data-zoom="whole"]').click(); },
    function () {
      p.whole = svg.style.transform;
      // Panzoom animates its buttons (a CSS transition on transform): the box measured is
      // the one the transition ends on, not a frame of it.
      var transition = svg.style.transition;
      svg.style.transition = 'none';
      p.whole_width = svg.getBoundingClientRect().width;
      svg.style.transition = transition;
      p.box_width = box.getBoundingClientRect().width;
      document.querySelector('[data-zoom="in"]').click();
    },
    function () { p.zoom_in = svg.style.transform; done(); }
  ];
  function next(i) {
    if (i === steps.length) return;
    setTimeout(function () { steps[i](); next(i + 1); }, 200);
  }
  next(0);
})();
</script>"""


def scale_of(transform):
    m = re.search(r"scale\(([0-9.eE+-]+)\)", transform or "")
    return float(m.group(1)) if m else None


def check_pan_zoom(binary, report, tmp):
    """Failures of the step graph's pan and zoom, from a probed copy of the page."""
    with open(report, encoding="utf-8") as f:
        page = f.read()
    at = page.rfind("</body>")
    if at < 0:
        return ["the page has no </body>"]
    probed = os.path.join(tmp, "probed-report.html")
    with open(probed, "w", encoding="utf-8") as f:
        f.write(page[:at] + PROBE + page[at:])
    run = chromium(binary, "--dump-dom", "file://" + probed)
    scan = ChartScan()
    scan.feed(run.stdout)
    raw = scan.root_attrs.get("data-probe")
    if not raw:
        return ["pan/zoom probe did not run (chromium exited %d)" % run.returncode]
    p = json.loads(raw)
    failures = []
    if p.get("ready") != "ready":
        failures.append("pan/zoom not initialised on #graph-step: %r" % p.get("ready"))
    if not p.get("inside"):
        failures.append("the step graph's SVG is not directly inside the pan/zoom box #graph-step")
    start, wheel, whole, zoom_in = (scale_of(p.get(k)) for k in ("start", "wheel", "whole", "zoom_in"))
    if start is None or not start > 0:
        failures.append("the step graph has no initial scale: transform %r" % p.get("start"))
        return failures
    if not p.get("nodes"):
        failures.append("the step graph has no node")
    if p.get("start_outside"):
        failures.append("the first view of the step graph leaves %d of its %d nodes outside the "
                        "box (e.g. %s)" % (len(p["start_outside"]), p["nodes"], p["start_outside"][:3]))
    if wheel is None or not wheel > start:
        failures.append("wheel up did not zoom in: %r -> %r" % (p.get("start"), p.get("wheel")))
    if whole is None or abs(whole - start) > 1e-9 or p.get("whole_width", 0) > p.get("box_width", 0) + 1:
        failures.append("'whole graph' did not go back to the first view, the graph fitted to the "
                        "box: %r (first %r), %s px wide in %s px"
                        % (p.get("whole"), p.get("start"), p.get("whole_width"), p.get("box_width")))
    if zoom_in is None or not zoom_in > start:
        failures.append("the + button did not zoom in: %r" % p.get("zoom_in"))
    return failures


def check_quotient(dom):
    """Failures of the quotient graph beside the step graph."""
    title = re.search(r"<h1>[^<]*?, (\d+) threads</h1>", dom)
    if not title:
        return ["no '<N> threads' in the page's title"]
    k = int(title.group(1))
    scan = GraphScan("graph-quotient")
    scan.feed(dom)
    nodes = [i for i in scan.items if i["class"] == "node"]
    edges = [i for i in scan.items if i["class"] == "edge"]
    failures = []
    names = sorted(n["title"] for n in nodes)
    want = sorted("p%d" % p for p in range(k))
    if names != want:
        return ["quotient graph nodes %s, expected %s" % (names, want)]
    tasks = share = 0.0
    for n in nodes:
        t = n["texts"]
        load = re.fullmatch(r"work [0-9.]+ (ns|µs|ms|s) \(([0-9.]+)%\)", t[1]) if len(t) == 3 else None
        count = re.fullmatch(r"(\d+) tasks?", t[2]) if len(t) == 3 else None
        if t[:1] != [n["title"]] or not load or not count:
            failures.append("quotient node %s labelled %r, expected [name, work (share %%), tasks]"
                            % (n["title"], t))
            continue
        share += float(load.group(2))
        tasks += int(count.group(1))
    step_tasks = re.search(r">(\d+) tasks · (\d+) dependencies", dom)
    if not step_tasks:
        failures.append("the step graph's title has no task count")
    elif int(step_tasks.group(1)) != tasks:
        failures.append("quotient nodes hold %d tasks, the step graph %s" % (tasks, step_tasks.group(1)))
    if abs(share - 100) > 0.05 * k + 0.1:  # shares rounded to 3 significant digits
        failures.append("quotient node shares add up to %.2f %%" % share)
    if k > 1 and not edges:
        failures.append("the quotient graph has no edge on %d processors" % k)
    for e in edges:
        text = " / ".join(e["texts"])
        if not re.fullmatch(r"\d+ deps?( \(\d+ carried\))? / [0-9.]+ (B|KiB|MiB|GiB) / \d+ signals?", text):
            failures.append("quotient edge %s labelled %r, expected 'N deps / bytes / N signals'"
                            % (e["title"], text))
    return failures


def check_explain(dom, charts):
    """Failures of the lost time's stacked bars (per step, per run) and of the executed
    critical path outlined on the timeline (tgraph explain's view of the demo's replay)."""
    failures = []
    for cid in ("chart-lost-steps", "chart-lost-runs"):
        if cid not in charts:
            failures.append("no %s chart (the lost time by cause)" % cid)
        elif not charts[cid]["drawn"]:
            failures.append("%s holds no drawn chart" % cid)
    bars = re.search(r'id="chart-lost-steps".*?role-mark marks"[^>]*>(.*?)</g>', dom, re.S)
    if bars and bars.group(1).count("<path") < 2:
        failures.append("chart-lost-steps draws %d bar segments" % bars.group(1).count("<path"))
    path = re.search(r'class="mark-rect role-mark critical_path_marks"[^>]*>(.*?)</g>', dom, re.S)
    if not path:
        failures.append("the timeline has no critical-path layer (outlined bodies)")
    elif path.group(1).count("<path") < 1:
        failures.append("the timeline's critical-path layer draws no body")
    # The same executed path on the step graph: its title names it, with its instances.
    graph = re.search(r'id="graph-step"[^>]*>(.*?)</svg>', dom, re.S)
    drawn = graph and re.search(r'executed critical path \(thick, double border\): [^<]*? over (\d+) task instances',
                                graph.group(1))
    if not drawn:
        failures.append("the step graph does not draw the executed critical path")
    elif int(drawn.group(1)) < 1:
        failures.append("the step graph's executed critical path has no task instance")
    return failures


def chromium(binary, *args):
    cmd = [binary, "--headless", "--disable-gpu", "--no-sandbox", "--no-first-run",
           "--disable-extensions", "--disable-background-networking", "--enable-logging=stderr",
           "--v=0", "--virtual-time-budget=" + BUDGET_MS, *args]
    return subprocess.run(cmd, capture_output=True, text=True, timeout=300)


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--tgraph", help="tgraph binary (runs `tgraph demo` when --report is not given)")
    p.add_argument("--chromium", default="chromium")
    p.add_argument("--report", help="an existing report to check")
    p.add_argument("--screenshot", required=True, help="PNG written here")
    p.add_argument("--steps", default="3", help="demo steps")
    args = p.parse_args()

    with tempfile.TemporaryDirectory() as tmp:
        report = args.report
        if not report:
            demo = subprocess.run([args.tgraph, "demo", "--steps", args.steps, "--repeat", "1", "--out", tmp],
                                  capture_output=True, text=True, timeout=900)
            if demo.returncode != 0:
                print("FAIL: tgraph demo exited %d:\n%s" % (demo.returncode, demo.stderr), file=sys.stderr)
                return 1
            last = demo.stdout.strip().splitlines()[-1] if demo.stdout.strip() else ""
            if not last.startswith("report: "):
                print("FAIL: tgraph demo does not end by printing the report's path: %r" % last, file=sys.stderr)
                return 1
            if "starpu" in subprocess.run([args.tgraph, "replay", "--help"], capture_output=True,
                                          text=True).stdout and "\nstarpu " not in demo.stdout:
                print("note: the demo table has no starpu row (starpu not in this build)")
            report = last[len("report: "):]
        url = "file://" + os.path.abspath(report)

        dom_run = chromium(args.chromium, "--dump-dom", url)
        if dom_run.returncode != 0:
            print("FAIL: chromium --dump-dom exited %d:\n%s" % (dom_run.returncode, dom_run.stderr[-4000:]),
                  file=sys.stderr)
            return 1
        failures = []
        # Chromium's log of the page's console: uncaught exceptions and errors.
        for line in dom_run.stderr.splitlines():
            if "CONSOLE" in line and re.search(r"Uncaught|Error|error", line):
                failures.append("console: " + line.strip())
        scan = ChartScan()
        scan.feed(dom_run.stdout)
        errors = scan.root_attrs.get("data-js-errors")
        if errors:
            failures.append("the page recorded JavaScript errors: " + errors)
        if not scan.charts:
            failures.append("no chart container in the page")
        for cid, state in scan.charts.items():
            if state["error"]:
                failures.append("chart %s shows an error" % cid)
            elif not state["drawn"]:
                failures.append("chart %s holds no non-empty SVG or canvas" % cid)
        declared = scan.body_attrs.get("data-charts")
        rendered = scan.body_attrs.get("data-charts-rendered", "0")
        if declared is None or declared != rendered:
            failures.append("charts declared %s, rendered %s" % (declared, rendered))

        failures += check_quotient(dom_run.stdout)
        failures += check_explain(dom_run.stdout, scan.charts)
        failures += check_pan_zoom(args.chromium, report, tmp)

        shot = chromium(args.chromium, "--hide-scrollbars", "--window-size=1280,4200",
                        "--screenshot=" + os.path.abspath(args.screenshot), url)
        if shot.returncode != 0 or not os.path.exists(args.screenshot) or os.path.getsize(args.screenshot) == 0:
            failures.append("no screenshot (chromium exited %d)" % shot.returncode)

        if failures:
            for f in failures:
                print("FAIL: " + f, file=sys.stderr)
            return 1
        print("report %s: %d charts rendered, no JavaScript error, step graph pans and zooms, "
              "quotient graph drawn; screenshot %s" % (report, len(scan.charts), args.screenshot))
        return 0


if __name__ == "__main__":
    sys.exit(main())
