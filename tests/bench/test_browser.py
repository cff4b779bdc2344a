"""The bench in a real browser: Debian's chromium, headless, driven by Selenium against a live server.

Set ``PNEUMORPH_SCREENSHOTS=1`` to write the screenshots of ``docs/bench.md`` into
``docs/figures/``.
"""

from __future__ import annotations

import os
import shutil
import socket
import threading
import time
from pathlib import Path

import pytest

pytest.importorskip("selenium")
uvicorn = pytest.importorskip("uvicorn")
CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
DRIVER = shutil.which("chromedriver")
if not (CHROMIUM and DRIVER):
    pytest.skip("Debian's chromium and chromium-driver are not installed (tests/browser-deps.sh installs them)",
                allow_module_level=True)

from selenium import webdriver  # noqa: E402
from selenium.webdriver.chrome.options import Options  # noqa: E402
from selenium.webdriver.chrome.service import Service  # noqa: E402
from selenium.webdriver.common.action_chains import ActionChains  # noqa: E402
from selenium.webdriver.common.by import By  # noqa: E402
from selenium.webdriver.common.keys import Keys  # noqa: E402
from selenium.webdriver.support.ui import Select  # noqa: E402

from pneumorph.bench import create_app  # noqa: E402

FIGURES = Path(__file__).resolve().parents[2] / "docs" / "figures"
pytestmark = pytest.mark.browser


@pytest.fixture(scope="module")
def server(tmp_path_factory: pytest.TempPathFactory):  # type: ignore[no-untyped-def]
    root = tmp_path_factory.mktemp("browser")
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    app = create_app(state_dir=root / "state", cache=root / "cache.sqlite", answer_workers=1)
    srv = uvicorn.Server(uvicorn.Config(app, host="127.0.0.1", port=port, log_level="warning"))
    thread = threading.Thread(target=srv.run, daemon=True)
    thread.start()
    for _ in range(600):
        if srv.started:
            break
        time.sleep(0.05)
    assert srv.started, "the bench did not start"
    yield f"http://127.0.0.1:{port}/"
    srv.should_exit = True
    thread.join(10)


@pytest.fixture(scope="module")
def browser(server: str):  # type: ignore[no-untyped-def]
    options = Options()
    options.binary_location = CHROMIUM
    for arg in ("--headless=new", "--no-sandbox", "--disable-dev-shm-usage", "--window-size=1400,1000",
                "--use-angle=swiftshader", "--enable-unsafe-swiftshader"):
        options.add_argument(arg)
    driver = webdriver.Chrome(options=options, service=Service(DRIVER))
    driver.get(server)
    yield driver
    driver.quit()


def _el(driver, id_: str):  # type: ignore[no-untyped-def]
    return driver.find_element(By.ID, id_)


def _wait(predicate, timeout: float = 10.0, step: float = 0.02) -> float:  # type: ignore[no-untyped-def]
    start = time.perf_counter()
    while time.perf_counter() - start < timeout:
        if predicate():
            return time.perf_counter() - start
        time.sleep(step)
    raise AssertionError(f"not within {timeout} s")


def _answered(driver) -> bool:  # type: ignore[no-untyped-def]
    return _el(driver, "answer").get_attribute("data-state") == "ok"


def _shot(driver, name: str) -> None:  # type: ignore[no-untyped-def]
    if os.environ.get("PNEUMORPH_SCREENSHOTS") == "1":
        time.sleep(0.5)  # the 3D view follows its answer
        driver.save_screenshot(str(FIGURES / f"bench-{name}.png"))


def _retype(element, text: str) -> None:  # type: ignore[no-untyped-def]
    element.send_keys(Keys.CONTROL, "a")
    element.send_keys(text)


def test_the_page_opens_on_the_certified_design_of_the_default_target(browser) -> None:  # type: ignore[no-untyped-def]
    _wait(lambda: _answered(browser), timeout=30)
    assert _el(browser, "winner-design").text == "001111010001001"  # the main job's answer
    assert "36.0 kPa" in _el(browser, "winner-pressure").text
    assert _el(browser, "winner-error").text.startswith("7.405 mm")
    assert "optimum is this design" in _el(browser, "certificate").text
    assert len(browser.find_elements(By.CSS_SELECTOR, "#top-table tbody tr")) == 10
    _wait(lambda: "chain" in _el(browser, "shape-source").text)
    assert not [e for e in browser.get_log("browser") if e["level"] == "SEVERE"]
    _shot(browser, "default")


def test_a_new_amplitude_is_answered_within_a_second(browser) -> None:  # type: ignore[no-untyped-def]
    before = _el(browser, "answer").get_attribute("data-query-id")
    field = _el(browser, "amplitude")
    start = time.perf_counter()
    _retype(field, "20")
    _wait(lambda: _el(browser, "answer").get_attribute("data-query-id") != before and _answered(browser))
    latency = time.perf_counter() - start
    print(f"answer {latency:.3f} s after the change")
    assert latency < 1.0, f"the answer came {latency:.2f} s after the change"
    assert "A = 20 mm" in _el(browser, "winner-label").text


def test_a_helix_shows_the_view_from_above(browser) -> None:  # type: ignore[no-untyped-def]
    """A space curve opens the view from above (the target's z against the planar actuator's); sin closes it."""
    assert not _el(browser, "top-view").is_displayed()
    Select(_el(browser, "preset")).select_by_value("helix")
    _wait(lambda: "helix" in _el(browser, "winner-label").text and _answered(browser))
    _wait(lambda: _el(browser, "top-view").is_displayed())
    drawn = browser.execute_script("const c = document.getElementById('top-plot');"
                                   "const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;"
                                   "let n = 0; for (let i = 0; i < d.length; i += 4)"
                                   "  if (d[i] === 224 && d[i + 1] === 123) n++;"
                                   "return n;")
    assert drawn > 50  # the target's orange (#e07b1a) line
    _shot(browser, "helix")
    # the spatial library's sideways units: a design that leaves the plane, seen from above, in 3D
    _retype(_el(browser, "amplitude"), "25")
    _wait(lambda: "A = 25 mm" in _el(browser, "winner-label").text and _answered(browser))
    before = _el(browser, "answer").get_attribute("data-query-id")
    Select(_el(browser, "unit")).select_by_value("spatial")
    _wait(lambda: _el(browser, "answer").get_attribute("data-query-id") != before and _answered(browser), timeout=30)
    assert _el(browser, "winner-design").text == "LaaaAlllAlAAAAa"  # the certified search's (BENCHMARKS.md)
    assert "optimum is one of 16 designs of all 1,073,741,824" in _el(browser, "certificate").text
    assert browser.find_elements(By.CSS_SELECTOR, "#design-boxes span.bl, #design-boxes span.bL")
    _wait(lambda: "chain" in _el(browser, "shape-source").text)
    actuator = browser.execute_script("const c = document.getElementById('top-plot');"
                                      "const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;"
                                      "let n = 0, lo = c.height, hi = 0;"
                                      "for (let i = 0; i < d.length; i += 4) if (d[i] === 11 && d[i + 1] === 107) {"
                                      "  n++; const y = Math.floor(i / 4 / c.width);"
                                      "  lo = Math.min(lo, y); hi = Math.max(hi, y); }"
                                      "return [n, hi - lo];")
    assert actuator[0] > 50 and actuator[1] > 40  # the actuator's blue (#0b6bcb) line climbs across the width
    assert not [e for e in browser.get_log("browser") if e["level"] == "SEVERE"]
    _shot(browser, "helix-spatial")
    Select(_el(browser, "unit")).select_by_value("builtin")
    _wait(lambda: _el(browser, "winner-design").text != "LaaaAlllAlAAAAa" and _answered(browser), timeout=30)
    _retype(_el(browser, "amplitude"), "20")
    _wait(lambda: "A = 20 mm" in _el(browser, "winner-label").text and _answered(browser))
    Select(_el(browser, "preset")).select_by_value("sin")
    _wait(lambda: not _el(browser, "top-view").is_displayed() and _answered(browser))


def test_an_expression_and_a_bad_one(browser) -> None:  # type: ignore[no-untyped-def]
    Select(_el(browser, "target-kind")).select_by_value("expression")
    field = _el(browser, "expression")
    _retype(field, "y = 0.3*x")
    _wait(lambda: "0.3*x" in _el(browser, "winner-label").text and _answered(browser))
    good = _el(browser, "winner-design").text
    assert _el(browser, "expression-error").text == ""
    _retype(field, "y = __import__('os').getcwd()")
    _wait(lambda: _el(browser, "expression-error").text != "")
    assert "__import__" in _el(browser, "expression-error").text
    assert _el(browser, "winner-design").text == good  # the last good answer stays
    assert _el(browser, "answer").get_attribute("data-state") == "error"
    _shot(browser, "expression-error")
    _retype(field, "y = 0.3*x")
    _wait(lambda: _el(browser, "expression-error").text == "" and _answered(browser))


def test_a_drawn_curve(browser) -> None:  # type: ignore[no-untyped-def]
    Select(_el(browser, "target-kind")).select_by_value("curve")
    canvas = _el(browser, "draw-canvas")
    w = canvas.size["width"]
    chain = ActionChains(browser).move_to_element_with_offset(canvas, -w // 2 + 12, 0).click_and_hold()
    for i in range(1, 41):  # a rising then falling stroke along the whole length
        chain = chain.move_by_offset((w - 30) // 40, -3 if i < 20 else 3)
    chain.release().perform()
    _wait(lambda: "curve" in _el(browser, "winner-label").text and _answered(browser))
    assert len(_el(browser, "winner-design").text) == 15
    _shot(browser, "drawn")


def test_a_curve_drawn_in_two_views(browser) -> None:  # type: ignore[no-untyped-def]
    """The side view and, below it, the view from above: the answer draws its view from above (the target's z)."""
    Select(_el(browser, "target-kind")).select_by_value("curve")
    _el(browser, "draw-clear").click()
    _stroke(browser, "draw-canvas", 1)
    _wait(lambda: _answered(browser) and not _el(browser, "top-view").is_displayed())  # planar: no view from above
    _stroke(browser, "draw-top-canvas", 1)
    _wait(lambda: _answered(browser) and _el(browser, "top-view").is_displayed())
    assert "curve" in _el(browser, "winner-label").text and len(_el(browser, "winner-design").text) == 15
    _shot(browser, "drawn-two-views")


def test_a_drawn_hook_is_a_path(browser) -> None:  # type: ignore[no-untyped-def]
    """A stroke along the axis that curls up and back past vertical: answered as a path, the design's centres (as
    the model reports them) drawn against it."""
    import numpy as np

    browser.get_log("browser")  # the earlier tests' entries (a refused expression among them)
    Select(_el(browser, "target-kind")).select_by_value("curve")
    _el(browser, "draw-clear").click()  # the earlier test's view from above too
    canvas = _el(browser, "draw-canvas")
    w = canvas.size["width"]
    px = w / 440 * 400 / 157.5  # CSS px per mm (draw.js: 20 px margins on a 440 px wide canvas)
    theta = np.radians(np.linspace(0.0, 200.0, 40))
    arc = np.c_[62 + 34 * np.sin(theta), 34 * (1 - np.cos(theta))]
    mm = np.r_[np.c_[np.linspace(0.0, 62.0, 20), np.zeros(20)], arc]
    at = np.round(np.c_[mm[:, 0] * px, -mm[:, 1] * px]).astype(int)  # from the base on the axis, y down on screen
    chain = ActionChains(browser, duration=20)  # ms a move: 60 moves in a second
    chain = chain.move_to_element_with_offset(canvas, -w // 2 + round(20 * w / 440) + 1, 0).click_and_hold()
    for step in np.diff(at, axis=0):
        chain = chain.move_by_offset(int(step[0]), int(step[1]))
    chain.release().perform()
    _wait(lambda: _el(browser, "winner-label").text.startswith("path: path through") and _answered(browser),
          timeout=30)
    assert len(_el(browser, "winner-design").text) == 15
    assert _el(browser, "plot-title").text.startswith("Path")
    assert "matched as a path" in _el(browser, "stroke-kind").text
    orange = browser.execute_script("const c = document.getElementById('profile-plot');"
                                    "const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;"
                                    "let n = 0, lo = c.height, hi = 0;"
                                    "for (let i = 0; i < d.length; i += 4) if (d[i] === 224 && d[i + 1] === 123) {"
                                    "  n++; const y = Math.floor(i / 4 / c.width);"
                                    "  lo = Math.min(lo, y); hi = Math.max(hi, y); }"
                                    "return [n, hi - lo];")
    assert orange[0] > 100 and orange[1] > 100  # the path (#e07b1a) drawn, climbing most of the plot's height
    assert not [e for e in browser.get_log("browser") if e["level"] == "SEVERE"]
    _shot(browser, "path")
    _el(browser, "draw-clear").click()


def _stroke(browser, canvas_id: str, rise: int) -> None:  # type: ignore[no-untyped-def]
    canvas = _el(browser, canvas_id)
    w = canvas.size["width"]
    chain = ActionChains(browser).move_to_element_with_offset(canvas, -w // 2 + 12, 0).click_and_hold()
    for _ in range(40):  # a straight stroke along the whole length, rising by `rise` px a step
        chain = chain.move_by_offset((w - 30) // 40, -rise)
    chain.release().perform()


def test_stages_drawn_at_two_pressures(browser) -> None:  # type: ignore[no-untyped-def]
    """Two drawn stages at 18 and 45 kPa: one design for both, each stage's target drawn over the ramp."""
    browser.get_log("browser")  # the earlier tests' entries (a refused expression among them)
    Select(_el(browser, "target-kind")).select_by_value("stages")
    _el(browser, "stage-add").click()
    assert "draw the stage's curve first" in _el(browser, "stages-error").text
    _stroke(browser, "stage-canvas", 0)
    Select(_el(browser, "stage-pressure")).select_by_visible_text("18 kPa")
    _el(browser, "stage-add").click()
    _stroke(browser, "stage-canvas", 2)
    Select(_el(browser, "stage-pressure")).select_by_visible_text("45 kPa")
    _el(browser, "stage-add").click()
    items = browser.find_elements(By.CSS_SELECTOR, "#stage-list li")
    assert [i.text.split(":")[0] for i in items] == ["18 kPa", "45 kPa"]
    _wait(lambda: _el(browser, "winner-label").text.startswith("stages: 18 kPa") and "; 45 kPa" in
          _el(browser, "winner-label").text and _answered(browser))
    assert len(_el(browser, "winner-design").text) == 15 and "45.0 kPa" in _el(browser, "winner-pressure").text
    assert not [e for e in browser.get_log("browser") if e["level"] == "SEVERE"]
    _shot(browser, "stages")
    items[0].find_element(By.TAG_NAME, "button").click()  # remove the 18 kPa stage
    _wait(lambda: _el(browser, "winner-label").text.startswith("stages: 45 kPa") and _answered(browser))


def test_switching_model_and_verifying_by_fe_survives_a_reload(browser) -> None:  # type: ignore[no-untyped-def]
    Select(_el(browser, "target-kind")).select_by_value("preset")
    _retype(_el(browser, "amplitude"), "10")
    Select(_el(browser, "model")).select_by_value("2d")
    # docs/chain-model.md: the 2D model's certified optimum for the default target
    _wait(lambda: _el(browser, "winner-design").text == "001111010001000" and _answered(browser))
    _el(browser, "verify-button").click()
    _wait(lambda: _el(browser, "job-status").get_attribute("data-state") in ("done", "failed"), timeout=180, step=0.2)
    assert _el(browser, "job-status").get_attribute("data-state") == "done", _el(browser, "job-log").text
    assert "001111010001000" in _el(browser, "job-status").text and "by FE" in _el(browser, "job-status").text
    names = [a.text for a in browser.find_elements(By.CSS_SELECTOR, "#downloads a")]
    assert {"report.md", "run.zip", "profile.png"} <= set(names)
    browser.execute_script("document.getElementById('verify-button').scrollIntoView({block: 'center'})")
    _shot(browser, "verified")
    browser.refresh()
    _wait(lambda: _answered(browser), timeout=30)
    _wait(lambda: "verify" in _el(browser, "jobs").text and "done" in _el(browser, "jobs").text)
    assert _el(browser, "job-status").get_attribute("data-state") == "done"


def test_a_job_is_cancelled_from_the_page(browser) -> None:  # type: ignore[no-untyped-def]
    _wait(lambda: _answered(browser), timeout=30)
    _el(browser, "export-button").click()
    _wait(lambda: _el(browser, "job-cancel").is_displayed(), timeout=10)  # shown while the job is queued or running
    _el(browser, "job-cancel").click()
    _wait(lambda: _el(browser, "job-status").get_attribute("data-state") == "cancelled", timeout=15)
    _wait(lambda: not _el(browser, "job-cancel").is_displayed())
    _wait(lambda: "export cancelled" in _el(browser, "jobs").text)
    # (the earlier tests' refused expressions are in the log too)
    assert not [e for e in browser.get_log("browser") if e["level"] == "SEVERE" and "/api/jobs" in e["message"]]


def test_a_tip_goal_the_spatial_chain_cannot_score_is_refused_beside_the_target(browser) -> None:  # type: ignore[no-untyped-def]
    """The curl has no chain in space: over the spatial library it is refused at once, the search hint cleared."""
    Select(_el(browser, "model")).select_by_value("3d")
    Select(_el(browser, "target-kind")).select_by_value("tip")
    Select(_el(browser, "goal")).select_by_value("max-curl")
    _wait(lambda: "curl" in _el(browser, "winner-label").text and _answered(browser), timeout=30)
    Select(_el(browser, "unit")).select_by_value("spatial")
    _wait(lambda: "spatial library's chain" in _el(browser, "target-error").text, timeout=30)
    assert _el(browser, "answer").get_attribute("data-state") == "error"
    assert "searching" not in _el(browser, "answer-time").text
    Select(_el(browser, "unit")).select_by_value("builtin")
    _wait(lambda: _answered(browser) and _el(browser, "target-error").text == "", timeout=30)


@pytest.mark.slow
def test_an_object_on_the_page_is_drawn_with_its_contact(browser) -> None:  # type: ignore[no-untyped-def]
    """A circle before the 2D sin winner's free end: a bad radius is refused beside the object's fields; a good one
    brings the answer solved against it (2D FE with contact), the circle drawn and the nodes in contact in red."""
    Select(_el(browser, "target-kind")).select_by_value("preset")
    Select(_el(browser, "preset")).select_by_value("sin")
    Select(_el(browser, "model")).select_by_value("2d")
    _wait(lambda: _answered(browser), timeout=30)
    _retype(_el(browser, "object-r"), "0")
    _el(browser, "object-on").click()
    _wait(lambda: "radius must be a finite number > 0" in _el(browser, "obstacle-error").text, timeout=30)
    assert _el(browser, "answer").get_attribute("data-state") == "error"
    _retype(_el(browser, "object-r"), "4")
    _wait(lambda: _answered(browser) and _el(browser, "contact-text").is_displayed(), timeout=600)
    assert _el(browser, "obstacle-error").text == ""
    browser.execute_script("const s = document.getElementById('pressure-slider'); s.value = s.max;"
                           "s.dispatchEvent(new Event('input'));")
    text = _el(browser, "contact-text").text
    assert "2D FE with contact) at 45.0 kPa: force" in text and "in contact" in text
    red = browser.execute_script("const c = document.getElementById('profile-plot');"
                                 "const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;"
                                 "let n = 0; for (let i = 0; i < d.length; i += 4)"
                                 "  if (d[i] === 207 && d[i + 1] === 34 && d[i + 2] === 46) n++;"
                                 "return n;")
    assert red > 10  # the nodes in contact (#cf222e)
    _shot(browser, "object")
    _el(browser, "object-on").click()
    Select(_el(browser, "model")).select_by_value("3d")
    _wait(lambda: _answered(browser) and not _el(browser, "contact-text").is_displayed(), timeout=30)
