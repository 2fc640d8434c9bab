"""Shared by the report tests (tests/report): where the beamrail command and the sources are, runs
of beamrail and scripts/report, and headless Chromium. CTest passes BEAMRAIL_EXECUTABLE and
BEAMRAIL_SOURCE_DIR; scripts/test_setup installs the packages the tests need and scripts/test sets
BEAMRAIL_TEST_PACKAGES=installed, so that a missing package fails the test there (outside
scripts/test it skips it, with exit status 77 and the command that installs them)."""

import importlib
import json
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

BEAMRAIL = os.environ.get("BEAMRAIL_EXECUTABLE", "")
SOURCE = os.environ.get("BEAMRAIL_SOURCE_DIR",
                        os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..")))
STUDIES = os.path.join(SOURCE, "studies")
REPORT = os.path.join(SOURCE, "scripts", "report")


def require(*modules, programs=()):
    """Exits 77 (CTest: skipped) when a module or program is missing, unless the test set-up ran
    (then it is a failure)."""
    missing = []
    for m in modules:
        try:
            importlib.import_module(m)
        except ImportError:
            missing.append(m)
    missing += [p for p in programs if not shutil.which(p)]
    if not BEAMRAIL or not os.path.exists(BEAMRAIL):
        print(f"BEAMRAIL_EXECUTABLE={BEAMRAIL!r} is not the beamrail command", file=sys.stderr)
        sys.exit(1)
    if not missing:
        return
    message = (f"missing {', '.join(missing)}: scripts/test_setup installs the packages of the "
               "report tests")
    print(message, file=sys.stderr)
    sys.exit(1 if os.environ.get("BEAMRAIL_TEST_PACKAGES") == "installed" else 77)


def run(args, expect=0, cwd=None):
    """Runs the beamrail command; returns (stdout, stderr); fails on another exit status."""
    p = subprocess.run([BEAMRAIL] + args, capture_output=True, text=True, cwd=cwd)
    if p.returncode != expect:
        raise AssertionError(f"beamrail {' '.join(args)}: exit status {p.returncode}, expected "
                             f"{expect}\n{p.stdout}\n{p.stderr}")
    return p.stdout, p.stderr


def report(results, expect=0, extra=()):
    p = subprocess.run([REPORT, results, *extra], capture_output=True, text=True)
    if p.returncode != expect:
        raise AssertionError(f"scripts/report {results}: exit status {p.returncode}, expected "
                             f"{expect}\n{p.stdout}\n{p.stderr}")
    return p.stdout, p.stderr


def load(path):
    with open(path) as f:
        return json.load(f)


def rows(path):
    """A CSV table as a list of dicts."""
    import csv
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def study(name):
    with open(os.path.join(STUDIES, name + ".json")) as f:
        return json.load(f)


def write_study(folder, name, document):
    path = os.path.join(folder, name + ".json")
    with open(path, "w") as f:
        json.dump(document, f)
    return path


def pointer(document, p):
    """The value at JSON pointer p (RFC 6901)."""
    value = document
    for part in p.lstrip("/").split("/") if p else []:
        part = part.replace("~1", "/").replace("~0", "~")
        value = value[int(part)] if isinstance(value, list) else value[part]
    return value


def chromium():
    """Headless Chromium (Debian's) through chromedriver, with a fresh profile; the browser's
    console is kept."""
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service
    options = webdriver.ChromeOptions()
    options.binary_location = "/usr/bin/chromium"
    profile = tempfile.mkdtemp(prefix="beamrail-chromium-")
    for a in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-quic",
              "--no-first-run", "--disable-background-networking", "--disable-component-update",
              "--disable-sync", "--enable-unsafe-swiftshader", "--window-size=1280,1600",
              f"--user-data-dir={profile}"):
        options.add_argument(a)
    options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    driver = webdriver.Chrome(service=Service("/usr/bin/chromedriver"), options=options)
    driver.beamrail_profile = profile
    return driver


def close(driver):
    profile = getattr(driver, "beamrail_profile", None)
    driver.quit()
    if profile:
        shutil.rmtree(profile, ignore_errors=True)


class TempDir(unittest.TestCase):
    """A test case with a fresh temporary folder in self.dir."""

    def setUp(self):
        self.dir = tempfile.mkdtemp(prefix="beamrail-report-test-")
        self.addCleanup(shutil.rmtree, self.dir, True)
