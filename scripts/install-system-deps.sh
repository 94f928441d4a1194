#!/usr/bin/env bash
# Install the Debian packages named on the command line when they are missing.
# Used by `make setup`; a no-op when everything is present. With --optional first (make
# browser-deps: chromium for the replay's browser tests), a failure only says what is skipped.
set -uo pipefail
what="simulation works, videos need EGL or OSMesa (cellsim says which when it cannot render)"
if [ "${1:-}" = "--optional" ]; then
  shift
  what="the tests that need them are skipped, with the reason"
fi
missing=()
for p in "$@"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0
if ! command -v apt-get >/dev/null 2>&1; then
  echo "cellsim: missing system packages ${missing[*]} and no apt-get to install them;" \
       "install their equivalents for your system ($what)" >&2
  exit 0  # rendering degrades with a clear message; simulation still works
fi
SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  if command -v sudo >/dev/null 2>&1; then SUDO="sudo"; else
    echo "cellsim: please install: ${missing[*]} (needs root; $what)" >&2; exit 0; fi
fi
echo "cellsim: installing system packages: ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
if ! { $SUDO apt-get update -qq && \
       $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null; }; then
  echo "cellsim: warning: could not install ${missing[*]}; $what" >&2
fi
