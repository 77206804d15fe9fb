#!/usr/bin/env bash
# Set up .venv with the CPU build of PyTorch, the core and every built-in plugin.
#   ./install.sh         runtime
#   ./install.sh --dev   runtime plus the test and lint tools, and the optional plugins
# Optional plugins (heavy dependencies) are installed with --dev only; install one by hand
# with: .venv/bin/pip install -e plugins/<name>
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
optional=("plugins/cphysfno-neuralop/")  # neuraloperator pulls wandb and tensorly (~90 MB)
for plugin in plugins/*/; do
  [[ -f "${plugin}pyproject.toml" ]] || continue
  if [[ -z "${extra}" && " ${optional[*]} " == *" ${plugin} "* ]]; then continue; fi
  args+=(-e "${plugin}")
done
$pip install --quiet "${args[@]}"
echo "cphysfno installed in .venv: run .venv/bin/cphysfno --help"
