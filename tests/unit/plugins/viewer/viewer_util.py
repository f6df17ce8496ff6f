"""What the viewer's tests share: a run with the viewer on a free port, its address, and its end."""
import os
import re
import signal
import subprocess
import time


class ViewedRun:
    """`ssx run SCENE --realtime --view 0 ...` in the background (or, with `replay`, `ssx replay RECORDING
    --view 0`); url is the page's address."""

    def __init__(self, ssx, scene, out_dir, *extra, replay=None):
        args = [ssx, "replay", replay, "--view", "0"] if replay else \
            [ssx, "run", scene, "--realtime", "--view", "0", "--out", out_dir]
        self.process = subprocess.Popen([*args, *extra], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        self.err_lines = []
        deadline = time.monotonic() + 30
        self.url = None
        while self.url is None:
            line = self.process.stderr.readline()
            if not line:
                raise RuntimeError("ssx ended before the viewer listened:\n" + "".join(self.err_lines))
            self.err_lines.append(line)
            found = re.search(r"viewer: (http://\S+)", line)
            if found:
                self.url = found.group(1)
            if time.monotonic() > deadline:
                raise RuntimeError("no viewer address in 30 s:\n" + "".join(self.err_lines))
        self.port = int(re.search(r":(\d+)/", self.url).group(1))

    def stop(self):
        """Ctrl-C, as a person stops a run; returns (exit status, everything it wrote to stderr)."""
        if self.process.poll() is None:
            self.process.send_signal(signal.SIGINT)
        out, err = self.process.communicate(timeout=60)
        return self.process.returncode, "".join(self.err_lines) + err


def chromium_available():
    return os.path.exists("/usr/bin/chromium") and os.path.exists("/usr/bin/chromedriver")


def headless_chromium(profile, width=1024, height=700):
    """Debian's Chromium, headless, WebGL through SwiftShader, driven by selenium (imported here: a
    test that needs none of it runs without it); its profile in the directory `profile`."""
    from selenium import webdriver
    from selenium.webdriver.chrome.options import Options
    from selenium.webdriver.chrome.service import Service

    options = Options()
    for a in ("--headless=new", "--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
              f"--window-size={width},{height}", f"--user-data-dir={profile}"):
        options.add_argument(a)
    return webdriver.Chrome(service=Service("/usr/bin/chromedriver"), options=options)


def wait_until(page, script, condition, problems, seconds=60):
    """Runs `script` in the page every 0.2 s until `condition` holds of what it returns, at most
    `seconds`; then what it returned last (a problem added to `problems` when it never held)."""
    deadline = time.monotonic() + seconds
    value = None
    while time.monotonic() < deadline:
        value = page.execute_script(script)
        if condition(value):
            return value
        time.sleep(0.2)
    problems.append(f"waited {seconds} s for {script!r}: last {value!r}")
    return value
