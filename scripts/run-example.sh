#!/usr/bin/env bash
# Installs moas-gui (scripts/setup.sh) and starts the server window on an example
# station whose switches are the built-in emulator.  Until the server window exists,
# it checks every example configuration instead.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
example="${1:-examples/big-station.moas}"
status=0
for f in examples/*.moas; do
    .venv/bin/moas-server --check "$f" || status=1
    echo
done
exit $status
