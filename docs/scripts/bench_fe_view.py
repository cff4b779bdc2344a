"""Screenshot of the bench after a 3D FE verification of the default target (docs/figures/bench-fe-shape.png).

    python docs/scripts/bench_fe_view.py     # needs chromium and chromedriver; about a minute

Starts ``pneumorph serve`` on a free port with a fresh state folder (the evaluation cache is
the default one, so a design solved before is not solved again), opens the page in headless
chromium, presses "Verify by FE" for the default target on the 3D model and waits for the
FE shape to replace the chain model's picture.
"""

from __future__ import annotations

import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from selenium import webdriver
from selenium.webdriver.chrome.options import Options
from selenium.webdriver.chrome.service import Service
from selenium.webdriver.common.by import By

OUT = Path(__file__).resolve().parents[1] / "figures" / "bench-fe-shape.png"


def main() -> None:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    with tempfile.TemporaryDirectory() as tmp:
        server = subprocess.Popen([sys.executable, "-m", "pneumorph", "serve", "--port", str(port), "--state", tmp])
        options = Options()
        options.binary_location = "/usr/bin/chromium"
        for arg in ("--headless=new", "--no-sandbox", "--window-size=1400,1000", "--use-angle=swiftshader",
                    "--enable-unsafe-swiftshader"):
            options.add_argument(arg)
        driver = webdriver.Chrome(options=options, service=Service("/usr/bin/chromedriver"))
        try:
            time.sleep(8)
            driver.get(f"http://127.0.0.1:{port}/")
            find = lambda i: driver.find_element(By.ID, i)  # noqa: E731
            while find("answer").get_attribute("data-state") != "ok":
                time.sleep(0.2)
            find("verify-button").click()
            while find("job-status").get_attribute("data-state") not in ("done", "failed"):
                time.sleep(1)
            while "FE" not in find("shape-source").text:
                time.sleep(0.2)
            driver.execute_script("window.scrollTo(0, 330)")
            time.sleep(1)
            driver.save_screenshot(str(OUT))
            print(find("job-status").text)
        finally:
            driver.quit()
            server.terminate()
            server.wait(10)


if __name__ == "__main__":
    main()
