#!/usr/bin/env bash
# Builds the frozen app from packaging/moas-gui.spec and tries it (scripts/smoke_frozen.py):
#   scripts/build-frozen.sh            build into dist/moas-gui, then try it
#   scripts/build-frozen.sh --no-build try what dist/moas-gui already holds
# Needs the venv of scripts/setup.sh; installs PyInstaller into it when missing.
# Prints its figures (build time, size, start-up times) at the end; docs/platforms.md
# has the last ones measured.  On Windows, run it from Git Bash; CI runs the same steps.
set -euo pipefail
cd "$(dirname "$0")/.."
py=".venv/bin/python"
[ -x "$py" ] || py=".venv/Scripts/python.exe"
[ -x "$py" ] || { echo "build-frozen: run scripts/setup.sh first" >&2; exit 2; }
dist="${DIST:-dist}"
work="${WORK:-build/pyinstaller}"
if [ "${1:-}" != "--no-build" ]; then
    "$py" -c "import PyInstaller" 2>/dev/null || "$py" -m pip install -q -e ".[freeze]"
    start=$(date +%s)
    "$py" -m PyInstaller --noconfirm --log-level WARN --distpath "$dist" --workpath "$work" \
        packaging/moas-gui.spec
    echo "build-frozen: built $dist/moas-gui in $(( $(date +%s) - start )) s"
fi
"$py" scripts/smoke_frozen.py "$dist/moas-gui"
