#!/usr/bin/env bash
# Installs Debian's Chromium and ChromeDriver when they are missing, then
# prints their versions. For a fresh Debian machine, run as root (CI).
# browser-check needs only chromium; chromium-driver is installed alongside so
# WebDriver-based tools find /usr/bin/chromedriver too.
set -euo pipefail

need=()
command -v chromium >/dev/null 2>&1 || need+=(chromium)
command -v chromedriver >/dev/null 2>&1 || need+=(chromium-driver)

if ((${#need[@]} > 0)); then
    echo "installing: ${need[*]}"
    export DEBIAN_FRONTEND=noninteractive
    apt-get update
    apt-get install -y --no-install-recommends chromium chromium-driver
else
    echo "chromium and chromium-driver already installed"
fi

# Debian's /usr/bin/chromium wrapper prints a harmless "[: ... unexpected
# operator" line on machines with two /dev/shm mounts; keep only the version.
chromium --version 2>/dev/null
chromedriver --version
