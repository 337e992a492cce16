#!/usr/bin/python3
# SPDX-License-Identifier: GPL-2.0-or-later
# The console in a real browser (Debian's chromium, headless, driven by python3-selenium):
# the page shows the values `i20 get` reads, an edit applies (and lands in the simulator's
# EEPROM), a refused value shows its refusal, the live plot gains points. A screenshot of
# each page goes to --out. Exit 77 (ctest SKIP) without chromium, its driver or selenium.
import argparse
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time

SKIP = 77

try:
    from selenium import webdriver
    from selenium.webdriver.chrome.options import Options
    from selenium.webdriver.chrome.service import Service
    from selenium.webdriver.common.by import By
    from selenium.common.exceptions import StaleElementReferenceException
    from selenium.webdriver.support.ui import WebDriverWait
except ImportError:
    print("SKIP: python3-selenium is not installed (scripts/install-deps --ci)")
    sys.exit(SKIP)


def find_browser():
    chromium = shutil.which("chromium")
    driver = shutil.which("chromedriver")
    if not chromium or not driver:
        print("SKIP: chromium or chromium-driver is not installed (scripts/install-deps --ci)")
        sys.exit(SKIP)
    return chromium, driver


def i20(binary, eeprom, *args):
    return subprocess.run([binary, "--sim", "--sim-eeprom", eeprom, *args], capture_output=True, text=True,
                          timeout=30)


def get_text(binary, eeprom, name):
    """What `i20 get NAME` prints after 'NAME = '."""
    r = i20(binary, eeprom, "get", name)
    assert r.returncode == 0, r.stderr
    return r.stdout.split(" = ", 1)[1].strip()


def start_console(binary, eeprom):
    # The simulated bus wanders by up to 3 V around its 320 V, sample to sample: the live page
    # must show it change.
    proc = subprocess.Popen([binary, "--sim", "--sim-eeprom", eeprom, "--sim-control", "noise busv 3", "console",
                             "--listen-port", "0"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.time() + 10
    while time.time() < deadline:
        line = proc.stdout.readline()
        m = re.search(r"(http://127\.0\.0\.1:\d+/\?token=[0-9a-f]{32})", line)
        if m:
            return proc, m.group(1)
    proc.kill()
    raise AssertionError("i20 console printed no URL")


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--i20", required=True)
    parser.add_argument("--out", required=True)
    args = parser.parse_args()
    chromium, driver_path = find_browser()
    os.makedirs(args.out, exist_ok=True)
    workdir = tempfile.mkdtemp(prefix="i20-console-browser-")
    eeprom = os.path.join(workdir, "card.eeprom")
    names = ["NVBRAKEONV", "NVMAXCURRENT", "NVKQP", "BUSOVERV"]
    expected = {n: get_text(args.i20, eeprom, n) for n in names}

    proc, url = start_console(args.i20, eeprom)
    options = Options()
    options.binary_location = chromium
    for flag in ("--headless", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage", "--window-size=1200,1000",
                 "--user-data-dir=" + os.path.join(workdir, "profile")):
        options.add_argument(flag)
    browser = webdriver.Chrome(service=Service(driver_path), options=options)
    # The page re-renders what it shows: an element found a moment ago may be replaced (stale)
    # by the time it is read; a wait looks again instead of failing.
    wait = WebDriverWait(browser, 15, ignored_exceptions=[StaleElementReferenceException])
    started = time.time()
    try:
        browser.get(url)
        wait.until(lambda b: b.find_element(By.TAG_NAME, "body").get_attribute("data-ready") == "true")
        assert "token" not in browser.current_url, browser.current_url  # the redirect dropped it
        bus = re.search(r"([0-9.]+) V", browser.find_element(By.ID, "identity").text)
        assert bus and 316.9 <= float(bus.group(1)) <= 323.1, browser.find_element(By.ID, "identity").text
        print(f"page usable after {time.time() - started:.2f} s")
        browser.save_screenshot(os.path.join(args.out, "overview.png"))

        browser.find_element(By.CSS_SELECTOR, "button[data-page=params]").click()
        row = lambda n: browser.find_element(By.CSS_SELECTOR, f"tr[data-name={n}] td.value")
        wait.until(lambda b: b.find_elements(By.CSS_SELECTOR, "tr[data-name=NVKQP]"))
        for n in names:
            assert row(n).text == expected[n], f"{n}: page {row(n).text!r}, i20 get {expected[n]!r}"
        browser.save_screenshot(os.path.join(args.out, "parameters.png"))

        outcome = lambda: browser.find_element(By.ID, "run-outcome")
        browser.find_element(By.CSS_SELECTOR, "input[name=NVKQP]").send_keys("66")
        browser.find_element(By.ID, "preview").click()
        wait.until(lambda b: b.find_elements(By.ID, "run-outcome") and outcome().get_attribute("data-outcome") == "dry-run")
        browser.find_element(By.ID, "apply").click()
        wait.until(lambda b: outcome().get_attribute("data-outcome") == "done")
        wait.until(lambda b: row("NVKQP").text == "66")
        browser.save_screenshot(os.path.join(args.out, "parameters-applied.png"))

        browser.find_element(By.CSS_SELECTOR, "input[name=NVKQP]").clear()
        browser.find_element(By.CSS_SELECTOR, "input[name=NVBRAKEONV]").send_keys("9999V")
        browser.find_element(By.ID, "preview").click()
        wait.until(lambda b: outcome().get_attribute("data-outcome") == "refused")
        assert "outside its valid range" in outcome().text, outcome().text
        assert not browser.find_element(By.ID, "apply").is_enabled()
        browser.save_screenshot(os.path.join(args.out, "parameters-refused.png"))

        browser.find_element(By.CSS_SELECTOR, "button[data-page=faults]").click()
        wait.until(lambda b: b.find_element(By.ID, "fault-title").text.startswith("FAULT"))
        browser.save_screenshot(os.path.join(args.out, "faults.png"))

        browser.find_element(By.CSS_SELECTOR, "button[data-page=live]").click()
        points = lambda: int(browser.find_element(By.ID, "plot").get_attribute("data-points") or 0)
        wait.until(lambda b: points() >= 5)
        first = points()
        buses = set()

        def bus_changed(_):
            buses.add(browser.find_element(By.ID, "live-busv").text)
            return points() >= first + 5 and len(buses) >= 3

        wait.until(bus_changed)
        for text in buses:
            assert 316.9 <= float(text.split()[0]) <= 323.1, text  # what the simulator's bus can be
        browser.save_screenshot(os.path.join(args.out, "live.png"))
        print(f"live plot: {first} then {points()} points; bus voltages shown: {sorted(buses)}")
    finally:
        browser.quit()
        proc.send_signal(signal.SIGINT)
        code = proc.wait(timeout=10)
    assert code == 130, f"i20 console exited {code} after Ctrl-C"
    assert get_text(args.i20, eeprom, "NVKQP") == "66"  # the edit is in the simulator's EEPROM
    assert get_text(args.i20, eeprom, "NVBRAKEONV") == expected["NVBRAKEONV"]  # the refused one is not
    shutil.rmtree(workdir, ignore_errors=True)
    print(f"screenshots in {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
