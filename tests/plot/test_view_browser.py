"""``plannerlab view`` in a real browser: headless Chromium (Debian's ``chromium`` and
``chromium-driver``, which ``.ci/run`` installs) driven by selenium loads the page, and
the tests look at what it drew.

What they assert: the server lists the scene nodes it sends (planned and executed robot,
scene, goals, traces) and reports the browser that connected; the screenshot's 3-D area
is not blank (the executed robot's orange and the plan's blue are there); moving the
timeline (from the browser's slider, and from the server's slider handle) changes the
picture; Ctrl-C ends the command with exit code 0
and no traceback. Every wait is bounded; no assertion depends on how fast the machine is.
"""

from __future__ import annotations

import io
import os
import queue
import shutil
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import plannerlab as pl

CHROMIUM = Path("/usr/bin/chromium")
CHROMEDRIVER = shutil.which("chromedriver") or "/usr/bin/chromedriver"
WINDOW = (1200, 800)
#: the 3-D area of a screenshot: left of the GUI panel, below the notification
VIEW_BOX = (slice(160, 780), slice(0, 780))
ROOT = Path(__file__).resolve().parents[2]

if not (CHROMIUM.exists() and Path(CHROMEDRIVER).exists()):
    if os.environ.get("CI"):
        raise RuntimeError("CI needs /usr/bin/chromium and chromedriver (.ci/run installs them)")
    pytest.skip(
        "needs Debian's chromium and chromium-driver (apt-get install chromium chromium-driver)",
        allow_module_level=True,
    )

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def plan_file(tmp_path_factory) -> Path:
    """A small plan: RRT-Connect on the Arm-Z pocket, seed 0, a 20 000-check budget."""
    problem = pl.load_problem("armz_pocket")
    budget = problem.budget.replace(max_collision_checks=20_000)
    plan = pl.solve(problem, "ompl.rrtconnect", 0, budget=budget)
    assert plan.solved, plan.legs[0].reason
    return plan.save(tmp_path_factory.mktemp("view") / "pocket.json")


@pytest.fixture(scope="module")
def executed_plan_file(plan_file, tmp_path_factory) -> Path:
    """The same plan executed in PyBullet, ``PLAN.exec.json`` beside it."""
    from plannerlab.record.files import versions
    from plannerlab.record.plan import ExecutionFile, execution_path

    plan = pl.Plan.load(plan_file)
    path = plan.save(tmp_path_factory.mktemp("view_exec") / "pocket.json")
    executions = pl.execute(plan, plan.load_problem())
    ExecutionFile.of(plan, path, executions, versions()).save(execution_path(path))
    return path


@pytest.fixture
def browser(tmp_path):
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    options = webdriver.ChromeOptions()
    options.binary_location = str(CHROMIUM)
    for arg in (
        "--headless=new",
        "--use-angle=swiftshader",
        "--enable-unsafe-swiftshader",
        "--disable-gpu",
        "--disable-background-networking",
        "--disable-component-update",
        "--disable-sync",
        "--no-first-run",
        f"--window-size={WINDOW[0]},{WINDOW[1]}",
        f"--user-data-dir={tmp_path / 'chromium-profile'}",
    ):
        options.add_argument(arg)
    if os.geteuid() == 0:
        options.add_argument("--no-sandbox")
    driver = webdriver.Chrome(service=Service(CHROMEDRIVER), options=options)
    driver.set_page_load_timeout(60)
    try:
        yield driver
    finally:
        driver.quit()


def screenshot(driver) -> np.ndarray:
    from PIL import Image

    return np.asarray(Image.open(io.BytesIO(driver.get_screenshot_as_png())).convert("RGB"))


def blue_pixels(img: np.ndarray) -> int:
    """Pixels of the 3-D area in the planned robot's blue (shaded: blue well above red)."""
    v = img[VIEW_BOX].astype(int)
    return int(np.sum((v[..., 2] > v[..., 0] + 60) & (v[..., 2] > 90)))


def orange_pixels(img: np.ndarray) -> int:
    """Pixels of the 3-D area in the executed robot's orange (red well above blue)."""
    v = img[VIEW_BOX].astype(int)
    return int(np.sum((v[..., 0] > v[..., 2] + 80) & (v[..., 1] > 60)))


def wait_for_picture(driver, ok, timeout_s: float, what: str) -> np.ndarray:
    """Screenshots every half second until ``ok(picture)`` (at most ``timeout_s``)."""
    end = time.monotonic() + timeout_s
    while True:
        img = screenshot(driver)
        if ok(img):
            return img
        if time.monotonic() > end:
            raise AssertionError(f"timed out after {timeout_s} s waiting for {what}")
        time.sleep(0.5)


def changed_fraction(a: np.ndarray, b: np.ndarray) -> float:
    d = np.abs(a[VIEW_BOX].astype(int) - b[VIEW_BOX].astype(int)).sum(axis=-1)
    return float(np.mean(d > 30))


def _lines(stream, out: queue.Queue) -> None:
    for line in stream:
        out.put(line)


def test_the_command_serves_a_page_chromium_draws_and_ctrl_c_ends_it(
    executed_plan_file, browser, tmp_path
):
    import json

    from selenium.webdriver.common.by import By
    from selenium.webdriver.common.keys import Keys

    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    proc = subprocess.Popen(
        [sys.executable, "-m", "plannerlab", "view", str(executed_plan_file), "--port", "0"]
        + ["--no-browser", "--json"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
    )
    events: queue.Queue = queue.Queue()
    threading.Thread(target=_lines, args=(proc.stdout, events), daemon=True).start()
    try:
        serving = json.loads(events.get(timeout=120))
        assert serving["event"] == "serving"
        nodes = serving["scene_nodes"]
        for node in (
            "/planned/links",
            "/planned/joints",
            "/executed/links",
            "/traces/executed",
            "/scene/boulder",
            "/goals/0/ball",
        ):
            assert node in nodes
        assert serving["legs"] == 1 and serving["executed_legs"] == 1

        browser.get(serving["url"])
        connected = json.loads(events.get(timeout=60))
        assert connected == {"event": "clients", "clients": 1, "scene_nodes": len(nodes)}

        # PyBullet's robot solid orange, the plan's blue wireframe over it
        first = wait_for_picture(
            browser,
            lambda img: orange_pixels(img) > 300 and blue_pixels(img) > 30,
            90,
            "the executed robot in orange and the planned one in blue",
        )
        (tmp_path / "start.png").write_bytes(browser.get_screenshot_as_png())
        # the timeline to its end, from the page: the slider's thumb and the End key
        thumb = browser.find_element(By.CSS_SELECTOR, "[role='slider']")
        thumb.send_keys(Keys.END)
        last = wait_for_picture(
            browser,
            lambda img: changed_fraction(first, img) > 0.005,
            60,
            "the picture to change after the slider moved",
        )
        (tmp_path / "end.png").write_bytes(browser.get_screenshot_as_png())
        assert orange_pixels(last) > 300
    finally:
        proc.send_signal(signal.SIGINT)
        try:
            rc = proc.wait(timeout=30)
        finally:
            if proc.poll() is None:
                proc.kill()
    stderr = proc.stderr.read()
    assert rc == 0, stderr
    assert "Traceback" not in stderr
    rest = []
    while not events.empty():
        rest.append(json.loads(events.get()))
    assert rest[-1] == {"event": "stopped"}


def test_moving_the_slider_from_python_redraws_the_page(plan_file, browser, tmp_path):
    viewer = pl.view(plan_file, port=0)
    try:
        browser.get(viewer.url)
        assert viewer.wait_for_client(60)
        first = wait_for_picture(
            browser, lambda img: blue_pixels(img) > 300, 90, "the robot drawn in blue"
        )
        (tmp_path / "start.png").write_bytes(browser.get_screenshot_as_png())
        viewer.slider.value = viewer.legs[0].frames // 2
        middle = wait_for_picture(
            browser,
            lambda img: changed_fraction(first, img) > 0.005,
            60,
            "the picture to change after the slider moved",
        )
        (tmp_path / "middle.png").write_bytes(browser.get_screenshot_as_png())
        # the panel says where the timeline is
        assert f"frame {viewer.legs[0].frames // 2 + 1} of" in viewer.info.content
        assert blue_pixels(middle) > 300
    finally:
        viewer.close()
