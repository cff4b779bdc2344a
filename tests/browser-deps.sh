#!/usr/bin/env bash
# Installs what the browser tests drive (tests/bench/test_browser.py): Debian's chromium and
# chromium-driver. Does nothing when both are present; where they cannot be installed (not
# Debian, not root) it says so and the browser tests are skipped with that reason.
if command -v chromium >/dev/null 2>&1 && command -v chromedriver >/dev/null 2>&1; then
    exit 0
fi
if ! command -v apt-get >/dev/null 2>&1; then
    echo "browser tests: no apt-get here; install chromium and its chromedriver to run them" >&2
    exit 0
fi
SUDO=""
if [ "$(id -u)" != "0" ]; then
    if sudo -n true 2>/dev/null; then SUDO="sudo -n"; else
        echo "browser tests: not root; run 'apt-get install chromium chromium-driver' to run them" >&2
        exit 0
    fi
fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get install -y -q chromium chromium-driver >/dev/null 2>&1 \
    || { $SUDO apt-get update -q >/dev/null 2>&1 && $SUDO apt-get install -y -q chromium chromium-driver >/dev/null 2>&1; } \
    || echo "browser tests: chromium could not be installed; they will be skipped" >&2
exit 0
