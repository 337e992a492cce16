#!/usr/bin/python3
# SPDX-License-Identifier: GPL-2.0-or-later
# The console in a real browser (Debian's chromium, headless, driven by python3-selenium):
# the page shows the values `i20 get` reads; two latched faults stand out on the overview and
# link to the Faults page, which explains them in `i20 faults`'s words and clears them; an
# edit made after its preview cannot be applied (Apply disabled, the server refuses the stale
# preview) and only a new preview's value is written, judged by what the simulated card holds;
# a refused value shows its refusal; the live plot shows bus voltage and temperature apart and
# gains points; every temperature is in degC. A screenshot of each page goes to --out.
# Exit 77 (ctest SKIP) without chromium, its driver or selenium.
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


# The simulated bus wanders by up to 3 V around its 320 V, sample to sample: the live page must
# show it change. Two faults latch before the console starts, their causes gone at once: an
# over-voltage (bit 9) and the enable input off (bit 1).
WORLD = ["noise busv 3", "fault 9 on", "fault 9 off", "enable off", "enable on"]


def start_console(binary, eeprom):
    controls = [word for line in WORLD for word in ("--sim-control", line)]
    proc = subprocess.Popen([binary, "--sim", "--sim-eeprom", eeprom, *controls, "console", "--listen-port", "0"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.time() + 10
    while time.time() < deadline:
        line = proc.stdout.readline()
        m = re.search(r"(http://127\.0\.0\.1:\d+/\?token=[0-9a-f]{32})", line)
        if m:
            return proc, m.group(1)
    proc.kill()
    raise AssertionError("i20 console printed no URL")


def api_get(browser, path):
    """What the console's API answers the page (the card as read now, not the page's words)."""
    return browser.execute_async_script(
        "const done = arguments[arguments.length - 1];"
        "fetch(arguments[0]).then((r) => r.json()).then(done, (e) => done({ error: String(e) }));", path)


def api_post(browser, path, body, headers):
    """A POST from the page's own origin, as a stale or forged page would send it: (status, JSON)."""
    return browser.execute_async_script(
        "const done = arguments[arguments.length - 1];"
        "fetch(arguments[0], { method: 'POST', body: arguments[1], headers: arguments[2] })"
        "  .then(async (r) => done([r.status, await r.json()]), (e) => done([0, { error: String(e) }]));",
        path, body, headers)


def card_raw(browser, name):
    """The raw value the card holds for NAME, read back through /api/params."""
    params = api_get(browser, "/api/params")["params"]
    return next(p["raw"] for p in params if p["name"] == name)


def check_faults(browser, wait, out):
    """Two latched faults: the overview marks them and links to the Faults page, which explains
    them in words; clearing them says what it cleared, and the card's FAULT is 0 after."""
    state = browser.find_element(By.ID, "overview-fault-state")
    assert state.get_attribute("data-latched") == "true", state.text
    assert "NOENABLEFAULT" in state.text and "BUSHIVFAULT" in state.text, state.text
    assert state.value_of_css_property("color") != browser.find_element(By.ID, "identity").value_of_css_property(
        "color"), "a latched fault looks like the rest of the overview"
    browser.save_screenshot(os.path.join(out, "overview.png"))
    browser.find_element(By.ID, "overview-faults-link").click()
    wait.until(lambda b: b.find_element(By.ID, "page-faults").is_displayed())
    wait.until(lambda b: "BUSHIVFAULT (bit 9" in b.find_element(By.ID, "fault-bits").text)
    text = browser.find_element(By.ID, "page-faults").text
    assert "Now: cause gone (BUSV is" in text, text  # `i20 faults`'s "now:" sentence
    assert "{" not in text and '"state"' not in text, text  # words, no JSON
    browser.save_screenshot(os.path.join(out, "faults.png"))
    browser.find_element(By.ID, "clear-faults").click()
    wait.until(lambda b: b.find_elements(By.ID, "clear-outcome"))
    said = browser.find_element(By.ID, "clear-outcome")
    assert said.get_attribute("data-outcome") == "done", said.text
    assert "Cleared: NOENABLEFAULT (bit 1), BUSHIVFAULT (bit 9)" in said.text, said.text
    assert api_get(browser, "/api/faults")["fault"]["value"] == 0  # the card's FAULT register
    browser.save_screenshot(os.path.join(out, "faults-cleared.png"))


def check_edit_after_preview(browser, wait, outcome, out):
    """Preview NVKQP=55, correct the box to 60: Apply is disabled and the server refuses the
    stale preview, so the card keeps its value; a new preview of 60 applies 60, as the card
    then holds."""
    before = card_raw(browser, "NVKQP")
    assert before not in (55, 60), before
    box = lambda: browser.find_element(By.CSS_SELECTOR, "input[name=NVKQP]")
    apply_button = lambda: browser.find_element(By.ID, "apply")
    box().send_keys("55")
    browser.find_element(By.ID, "preview").click()
    wait.until(lambda b: apply_button().is_enabled())
    assert outcome().get_attribute("data-outcome") == "dry-run", outcome().text
    stale_id = browser.execute_script("return previewed && previewed.id")
    assert stale_id, "the preview was given no id"

    box().clear()
    box().send_keys("60")
    assert not apply_button().is_enabled(), "Apply still enabled after an edit"
    assert browser.find_element(By.ID, "preview-outdated").is_displayed()
    browser.save_screenshot(os.path.join(out, "parameters-edited-after-preview.png"))
    status, data = api_post(browser, "/api/apply", "NVKQP=60", {"I20-Preview": stale_id})
    assert status == 409, (status, data)  # the server refuses what its preview did not show
    assert card_raw(browser, "NVKQP") == before  # neither 55 nor 60 written

    browser.find_element(By.ID, "preview").click()
    wait.until(lambda b: apply_button().is_enabled())
    assert "60" in outcome().text, outcome().text
    apply_button().click()
    wait.until(lambda b: outcome().get_attribute("data-outcome") == "done")
    assert "written, read back equal" in outcome().text and "intended" not in outcome().text, outcome().text
    assert card_raw(browser, "NVKQP") == 60
    browser.save_screenshot(os.path.join(out, "parameters-applied.png"))


def check_live_plot(browser):
    """Bus voltage and temperature each in a band of its own, one above the other: both seen."""
    # In one script: the plot is redrawn with every sample, so elements found apart go stale.
    bus, temperature, legend = browser.execute_script(
        "const box = (c) => { const e = document.querySelector('#plot .' + c);"
        "  if (!e) return null; const b = e.getBBox(); return [b.y, b.y + b.height]; };"
        "const legend = document.querySelector('#plot .legend-temperature');"
        "return [box('series-busv'), box('series-temperature'), legend && legend.textContent];")
    assert bus and temperature, (bus, temperature)
    assert bus[1] < temperature[0], f"the lines overlap: bus {bus}, temperature {temperature}"
    assert legend and "degC" in legend, legend


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
        browser.set_script_timeout(15)
        identity = browser.find_element(By.ID, "identity").text
        bus = re.search(r"([0-9.]+) V", identity)
        assert bus and 316.9 <= float(bus.group(1)) <= 323.1, identity
        assert re.search(r"Temperature [0-9.]+ degC", identity), identity  # the CLI's unit, everywhere
        print(f"page usable after {time.time() - started:.2f} s")
        check_faults(browser, wait, args.out)

        browser.find_element(By.CSS_SELECTOR, "button[data-page=params]").click()
        row = lambda n: browser.find_element(By.CSS_SELECTOR, f"tr[data-name={n}] td.value")
        wait.until(lambda b: b.find_elements(By.CSS_SELECTOR, "tr[data-name=NVKQP]"))
        for n in names:
            assert row(n).text == expected[n], f"{n}: page {row(n).text!r}, i20 get {expected[n]!r}"
        browser.save_screenshot(os.path.join(args.out, "parameters.png"))

        outcome = lambda: browser.find_element(By.ID, "run-outcome")
        check_edit_after_preview(browser, wait, outcome, args.out)
        wait.until(lambda b: row("NVKQP").text == "60")

        browser.find_element(By.CSS_SELECTOR, "input[name=NVKQP]").clear()
        browser.find_element(By.CSS_SELECTOR, "input[name=NVBRAKEONV]").send_keys("9999V")
        browser.find_element(By.ID, "preview").click()
        wait.until(lambda b: outcome().get_attribute("data-outcome") == "refused")
        assert "outside its valid range" in outcome().text, outcome().text
        assert not browser.find_element(By.ID, "apply").is_enabled()
        browser.save_screenshot(os.path.join(args.out, "parameters-refused.png"))

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
        check_live_plot(browser)
        # The faults cleared earlier stay cleared: the live view reads the same card.
        assert browser.find_element(By.ID, "live-fault").text.startswith("0x0000"), browser.find_element(
            By.ID, "live-fault").text
        assert browser.find_element(By.ID, "live-temp").text.endswith(" degC")
        for page in ("overview", "params", "faults", "live"):
            browser.find_element(By.CSS_SELECTOR, f"button[data-page={page}]").click()
            assert "°" not in browser.find_element(By.TAG_NAME, "main").text, page
        assert "°" not in browser.page_source  # every page as rendered, hidden ones too
        browser.save_screenshot(os.path.join(args.out, "live.png"))
        print(f"live plot: {first} then {points()} points; bus voltages shown: {sorted(buses)}")
    finally:
        browser.quit()
        proc.send_signal(signal.SIGINT)
        code = proc.wait(timeout=10)
    assert code == 130, f"i20 console exited {code} after Ctrl-C"
    assert get_text(args.i20, eeprom, "NVKQP") == "60"  # the re-previewed edit is in the simulator's EEPROM
    assert get_text(args.i20, eeprom, "NVBRAKEONV") == expected["NVBRAKEONV"]  # the refused one is not
    shutil.rmtree(workdir, ignore_errors=True)
    print(f"screenshots in {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
