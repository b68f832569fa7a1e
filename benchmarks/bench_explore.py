"""Benchmark of ``posturelab explore`` (run as a script, not a test).

``python benchmarks/bench_explore.py`` starts the explorer's server in-process, opens the
page in a headless system Chromium (Playwright), and moves the ankle stiffness slider
20 times (alternating values, each change waiting for the page to finish drawing). It
prints the median and largest round trip of one control change, measured by the page
from the change to the end of drawing (request, computation, JSON, Chart.js), against
the plain baseline of the same computation called in-process
(``posturelab.explore.compute_views``), without and with a 0.15 s feedback delay (the
delay adds the rightmost characteristic roots of the delay equation).

``--screenshot FILE.png`` then also sets an intrinsic-plus-active controller with a
0.12 s delay and saves the page (the README's picture, docs/images/explore.png).
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import time

from posturelab.explore import compute_views, parse_parameters
from posturelab.explore.browser import launch_chromium, running_server

CHANGES = 20


def browser_round_trips(page, delay: float) -> list[float]:
    page.fill("#feedback_delay", str(delay))
    done = int(page.evaluate("document.body.dataset.updates"))
    page.wait_for_function(f"Number(document.body.dataset.updates) > {done}")
    times = []
    for k in range(CHANGES):
        done = int(page.evaluate("document.body.dataset.updates"))
        page.locator('input[type=range][data-for="stiffness:ankle"]').fill(
            str(400 + 10 * (k % 2) + k))
        page.wait_for_function(f"Number(document.body.dataset.updates) > {done}")
        times.append(float(page.evaluate("document.body.dataset.roundTrip")) / 1000)
    return times


def in_process(delay: float) -> list[float]:
    times = []
    for k in range(CHANGES):
        p = parse_parameters({"stiffness:ankle": 400 + 10 * (k % 2) + k,
                              "feedback_delay": delay})
        t0 = time.perf_counter()
        compute_views(p)
        times.append(time.perf_counter() - t0)
    return times


def screenshot(page, path: str) -> None:
    """The page with intrinsic gains at 60 % and active ankle and hip gains, τ = 0.12 s."""
    for name, value in (("stiffness:ankle", 300), ("active_stiffness:ankle", 450),
                        ("active_viscosity:ankle", 120), ("active_stiffness:hip", 200),
                        ("active_viscosity:hip", 50), ("feedback_delay", 0.12),
                        ("step_speed", 0.5)):
        done = int(page.evaluate("document.body.dataset.updates"))
        page.fill(f"#{name}", str(value))
        page.wait_for_function(f"Number(document.body.dataset.updates) > {done}")
    page.evaluate("document.activeElement.blur(); window.scrollTo(0, 0)")
    page.wait_for_timeout(1200)  # the stick figure mid-sway
    page.screenshot(path=path, full_page=False)
    print(f"wrote {path}")


def main() -> None:
    from playwright.sync_api import sync_playwright

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--screenshot", metavar="FILE.png")
    args = parser.parse_args()

    print(f"posturelab explore benchmark: {platform.processor() or platform.machine()}, "
          f"{os.cpu_count()} CPUs; {CHANGES} slider changes per row")
    compute_views(parse_parameters({}))  # warm up (first-call imports)
    with running_server() as url, sync_playwright() as playwright:
        browser = launch_chromium(playwright)
        page = browser.new_page(viewport={"width": 1440, "height": 900})
        page.goto(url)
        page.wait_for_function("Number(document.body.dataset.updates) >= 1", timeout=60_000)
        for delay in (0.0, 0.15):
            trips = browser_round_trips(page, delay)
            base = in_process(delay)
            med, base_med = statistics.median(trips), statistics.median(base)
            print(f"feedback delay {delay:g} s: page round trip median {1000 * med:.0f} ms "
                  f"(largest {1000 * max(trips):.0f} ms); compute_views in-process median "
                  f"{1000 * base_med:.0f} ms; ratio {med / base_med:.1f}×")
        if args.screenshot:
            screenshot(page, args.screenshot)
        browser.close()


if __name__ == "__main__":
    main()
