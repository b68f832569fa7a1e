"""Shared test helpers: the explorer served on loopback and open in Debian's chromium,
driven by Playwright (CI installs both; elsewhere the browser tests skip without them)."""

import contextlib
import importlib.util
import os

import pytest

from posturelab.explore.browser import chromium_path

needs_browser = pytest.mark.skipif(
    (chromium_path() is None or importlib.util.find_spec("playwright") is None)
    and not os.environ.get("CI"),
    reason="needs Debian's chromium and Playwright (CI installs both)")


@contextlib.contextmanager
def explorer_page(timeout_ms: float = 60_000):
    """The explorer's page after its first redraw: yields (page, errors), ``errors`` the page
    errors seen so far; the browser and the server are closed after."""
    from playwright.sync_api import sync_playwright

    from posturelab.explore.browser import launch_chromium, running_server

    with running_server() as url, sync_playwright() as playwright:
        browser = launch_chromium(playwright)
        try:
            page = browser.new_page(viewport={"width": 1400, "height": 1000})
            errors: list[str] = []
            page.on("pageerror", lambda exc: errors.append(str(exc)))
            page.goto(url)
            page.wait_for_function("Number(document.body.dataset.updates) >= 1",
                                   timeout=timeout_ms)
            yield page, errors
        finally:
            browser.close()
