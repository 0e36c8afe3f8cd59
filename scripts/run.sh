#!/usr/bin/env bash
# Quick start, command 1: installs what is missing, builds, and prints handcentric's main report.
# Arguments are passed to `handcentric` (none: the main report).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bash "$root/scripts/install-deps.sh"
bash "$root/scripts/build.sh" >/dev/null
exec "${BUILD_DIR:-$root/build}/apps/handcentric" "$@"
