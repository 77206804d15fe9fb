#!/usr/bin/env bash
# Set up .venv with the CPU build of PyTorch, the core and every built-in plugin.
#   ./install.sh         runtime
#   ./install.sh --dev   runtime plus the test and lint tools
set -euo pipefail
cd "$(dirname "$0")"
python3 -m venv .venv
pip="./.venv/bin/python -m pip"
$pip install --quiet --upgrade pip
# Torch first: a bare `torch` requirement would otherwise pull a multi-GB CUDA build.
$pip install --quiet "torch==2.13.0"
extra=""
if [[ "${1:-}" == "--dev" ]]; then extra="[dev]"; fi
args=(-e ".${extra}")
for plugin in plugins/*/; do [[ -f "${plugin}pyproject.toml" ]] && args+=(-e "${plugin}"); done
$pip install --quiet "${args[@]}"
echo "cphysfno installed in .venv: run .venv/bin/cphysfno --help"
