"""``robotspec setup`` as a user meets it: command to first picture, change to validation shown.

Three figures on example-robot-data's xArm7 (drafted from its URDF), in Debian's headless
Chromium (software WebGL) driven by selenium: the setup command in a new process until the robot
is drawn in the page (peer: ``robotspec view`` of the spec it saves, the same drawing without
drafting and validating); a pick in the page that breaks the spec until validate's message is on
the page, and one that fixes it (median of the changes); and, without a browser, one change
validated on the PR2 (URDF + SRDF, the session's ``set_chain``) against ``check_spec`` of the
same spec (what ``robotspec validate`` does), which is most of that change's cost. Wall times on
a shared machine: software WebGL competes for its cores.

Run: ``python benchmarks/bench_setup.py [--repeat N]`` (needs example-robot-data, the view extra,
selenium, and chromium with chromium-driver). Prints medians.
"""

from __future__ import annotations

import argparse
import io
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from rows import Row, add_json_flag, erd_share, median_times, print_rows

FLAGS = (
    "--headless --no-sandbox --disable-gpu --disable-background-networking "
    "--disable-component-update --disable-sync --no-first-run --use-angle=swiftshader "
    "--enable-unsafe-swiftshader --window-size=1000,680"
).split()


def _browser(profile: Path) -> Any:
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    opts = webdriver.ChromeOptions()
    opts.binary_location = "/usr/bin/chromium"
    for flag in (*FLAGS, f"--user-data-dir={profile}"):
        opts.add_argument(flag)
    return webdriver.Chrome(service=Service("/usr/bin/chromedriver"), options=opts)


def _wait(cond: Callable[[], Any], timeout: float = 120.0, pause: float = 0.05) -> Any:
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        try:
            got = cond()
        except Exception:  # noqa: BLE001 - the page is still drawing
            got = None
        if got:
            return got
        time.sleep(pause)
    raise TimeoutError("the page did not get there")


def _drawn(d: Any) -> bool:
    """Whether the robot's coloured parts are on screen (blue chain pixels in the 3D area)."""
    from PIL import Image

    img = np.asarray(Image.open(io.BytesIO(d.get_screenshot_as_png())).convert("RGB"))
    area = img[:, 320 : img.shape[1] - 345].astype(np.int64)
    blue = (area[..., 2] - area[..., 0] > 60) & (area.max(axis=2) - area.min(axis=2) > 60)
    return int(blue.sum()) > 1500


def _first_picture(d: Any, cmd: list[str]) -> float:
    """Seconds from starting ``cmd`` (it prints its URL) to the robot drawn in ``d``."""
    t0 = time.perf_counter()
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    try:
        assert proc.stdout is not None
        line = proc.stdout.readline()
        url = next(w for w in line.split() if w.startswith("http://"))
        d.get(url)
        _wait(lambda: _drawn(d), pause=0.3)
        return time.perf_counter() - t0
    finally:
        proc.terminate()
        proc.wait(10)


def _changes(d: Any, repeat: int) -> float:
    """Median seconds from a pick (in the page) to validate's verdict shown, in process."""
    from selenium.webdriver.common.by import By

    from robotspec.setup import SetupSession
    from robotspec.setup.page import SetupPage

    urdf = erd_share() / "robots/xarm_description/urdf/xarm7.urdf"
    session = SetupSession.open(str(urdf), output=Path(tempfile.mkdtemp()) / "xarm.yaml")
    page = SetupPage(session, port=0)
    try:
        d.get(page.url)
        body = _wait(lambda: d.find_element(By.TAG_NAME, "body"))
        _wait(lambda: "open questions" in body.text)
        d.execute_script("document.querySelectorAll('canvas').forEach(c => c.style.display='none')")
        page._part.value = "chains.arm"
        page._select_part("chains.arm")
        parts = "//*[@role='tab' and @title='Parts']"
        _wait(lambda: d.find_element(By.XPATH, parts)).click()
        button = _wait(
            lambda: d.find_element(By.XPATH, "//button[normalize-space()='tip = picked link']")
        )
        times: list[float] = []
        for k in range(2 * repeat):
            tip, shown = ("link_eef", "✖ invalid") if k % 2 == 0 else ("link7", "✔ valid")
            page.select(tip)
            t0 = time.perf_counter()
            button.click()
            _wait(lambda shown=shown: shown in body.text, 30)  # type: ignore[misc]
            times.append(time.perf_counter() - t0)
        return statistics.median(times)
    finally:
        page.stop()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--repeat", type=int, default=3)
    add_json_flag(parser)
    args = parser.parse_args()
    say = (lambda *a, **k: None) if args.json else print
    robots = erd_share() / "robots"
    work = Path(tempfile.mkdtemp())
    urdf = robots / "xarm_description/urdf/xarm7.urdf"
    spec = work / "xarm.yaml"
    subprocess.run(
        [sys.executable, "-m", "robotspec", "init", str(urdf), "-o", str(spec)],
        check=True,
        capture_output=True,
    )
    setup = [sys.executable, "-m", "robotspec", "setup", str(urdf), "-o", str(work / "s.yaml")]
    setup += ["--port", "0"]
    view = [sys.executable, "-m", "robotspec", "view", str(spec), "--port", "0"]
    d = _browser(work / "profile")
    try:
        firsts: dict[str, list[float]] = {"setup": [], "view": []}
        for _ in range(args.repeat):
            for name, cmd in (("setup", setup), ("view", view)):
                d.get("about:blank")
                firsts[name].append(_first_picture(d, cmd))
        change = _changes(d, args.repeat)
    finally:
        d.quit()
    from robotspec.compiler import check_spec
    from robotspec.setup import SetupSession

    pr2 = robots / "pr2_description"
    session = SetupSession.open(
        str(pr2 / "urdf/pr2.urdf"), srdf=str(pr2 / "srdf/pr2.srdf"), output=work / "pr2.yaml"
    )
    session.save()
    tips = iter(["r_wrist_flex_link", "r_wrist_roll_link"] * 1000)
    ours, peer = median_times(
        [
            lambda: session.set_chain("chains.right_arm", tip=next(tips)),
            lambda: check_spec(work / "pr2.yaml"),
        ],
        args.repeat * 3,
    )
    setup_s, view_s = statistics.median(firsts["setup"]), statistics.median(firsts["view"])
    rows = [
        Row("xArm7: setup to first picture", setup_s, "robotspec view to first picture", view_s),
        Row("xArm7: a pick to validation shown", change, "", None),
        Row("PR2: one change validated (session)", ours, "check_spec of the spec", peer),
    ]
    say(f"{args.repeat} rounds, medians; headless Chromium, software WebGL")
    print_rows(rows, args.json)


if __name__ == "__main__":
    main()
