"""Screenshots of three pages of the built site (``make docs`` first).

Run: ``.venv/bin/python docs/screenshots/take_screenshots.py [SITE]`` (default
``docs/_build/html``). Uses Playwright with the system's Chromium (``/usr/bin/chromium``),
offline. Writes ``front-page.png``, ``tutorial.png`` (the first tutorial of the gallery; the
mathematics page when the gallery is empty) and ``cli-reference.png`` beside this script.
"""

from __future__ import annotations

import sys
from pathlib import Path

from playwright.sync_api import sync_playwright

HERE = Path(__file__).resolve().parent
CHROMIUM = "/usr/bin/chromium"
FLAGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-component-update",
    "--no-first-run",
]


def pages(site: Path) -> dict[str, Path]:
    """The pages to take: name -> HTML file."""
    tutorials = sorted((site / "auto_tutorials").glob("plot_*.html"))
    second = tutorials[0] if tutorials else site / "concepts" / "mathematics.html"
    return {
        "front-page": site / "index.html",
        "tutorial": second,
        "cli-reference": site / "reference" / "cli.html",
    }


def main(site: Path) -> None:
    """Write the three screenshots."""
    with sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path=CHROMIUM, args=FLAGS, headless=True)
        page = browser.new_page(viewport={"width": 1280, "height": 1000})
        # No request leaves the machine: anything that is not a local file fails the run.
        page.route(
            "**/*",
            lambda route: (
                route.continue_() if route.request.url.startswith("file://") else route.abort()
            ),
        )
        for name, path in pages(site).items():
            page.goto(path.as_uri())
            page.wait_for_load_state("load")
            out = HERE / f"{name}.png"
            page.screenshot(path=str(out), full_page=False)
            print(f"{out} <- {path}")  # noqa: T201
        browser.close()


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else HERE.parent / "_build" / "html")
