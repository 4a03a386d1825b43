#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Opens tgraph's HTML report in headless Chromium (no network) and checks it.

Fails when the page reports a JavaScript error (uncaught exception, console.error, a chart
that failed to render) or Chromium logs one, when a chart container holds no non-empty SVG
or canvas, or when fewer charts rendered than the page declared. Saves a PNG screenshot.

  browser_check.py --tgraph build/release/apps/tgraph --chromium /usr/bin/chromium \
      --screenshot report.png            # runs `tgraph demo` and checks its report
  browser_check.py --report r.html ...   # checks an existing page
"""
import argparse
import html.parser
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

        shot = chromium(args.chromium, "--hide-scrollbars", "--window-size=1280,4200",
                        "--screenshot=" + os.path.abspath(args.screenshot), url)
        if shot.returncode != 0 or not os.path.exists(args.screenshot) or os.path.getsize(args.screenshot) == 0:
            failures.append("no screenshot (chromium exited %d)" % shot.returncode)

        if failures:
            for f in failures:
                print("FAIL: " + f, file=sys.stderr)
            return 1
        print("report %s: %d charts rendered, no JavaScript error; screenshot %s" %
              (report, len(scan.charts), args.screenshot))
        return 0


if __name__ == "__main__":
    sys.exit(main())
