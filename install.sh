#!/usr/bin/env bash
# Set up .venv with PyTorch, the core and every built-in plugin (all editable).
#
#   ./install.sh          runtime, with the CPU build of PyTorch
#   ./install.sh --dev    also the test, lint and docs tools, and the optional plugins
#   ./install.sh --cuda   the default PyPI build of PyTorch (on Linux the CUDA one) instead
#   ./install.sh --cpu    the CPU build (the default; overrides CPHYSFNO_TORCH=cuda)
#   ./install.sh --help   this text
# Flags combine: ./install.sh --dev --cuda
#
# Environment:
#   CPHYSFNO_TORCH=cpu|cuda      the build of PyTorch when no --cpu/--cuda is given (cpu)
#   CPHYSFNO_TORCH_CPU_INDEX=URL where the CPU build comes from
#                                (https://download.pytorch.org/whl/cpu)
#   CPHYSFNO_INSTALL_DRY_RUN=1   print the commands it would run and run none of them
#
# PyTorch (torch==2.13.0) is installed first, before anything can require a bare `torch`:
#   cpu   with --index-url set to the CPU index, which has no multi-GB CUDA build. If that
#         index does not answer within 5 s (an offline mirror, a firewall), the plain
#         requirement goes to the configured package index instead; the script says which.
#   cuda  the plain requirement from the configured package index (PyPI: CUDA on Linux).
# A torch 2.13.0 that already imports in .venv is kept: any build for cpu (a CUDA build runs
# on the CPU too), a CUDA or ROCm build for cuda (a CPU build is uninstalled first).
# Optional plugins (heavy dependencies) are installed with --dev only; install one by hand
# with: .venv/bin/pip install -e plugins/<name>
set -euo pipefail
cd "$(dirname "$0")"

TORCH_VERSION="2.13.0"
CPU_INDEX="${CPHYSFNO_TORCH_CPU_INDEX:-https://download.pytorch.org/whl/cpu}"
OPTIONS="--dev, --cuda, --cpu, --help"

usage() {
  awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "$0"
}

dev=0
torch_build="${CPHYSFNO_TORCH:-cpu}"
for arg in "$@"; do
  case "${arg}" in
    --dev) dev=1 ;;
    --cuda) torch_build=cuda ;;
    --cpu) torch_build=cpu ;;
    -h | --help) usage; exit 0 ;;
    *) echo "install.sh: unknown option '${arg}'; the options are ${OPTIONS}" >&2; exit 2 ;;
  esac
done
if [[ "${torch_build}" != cpu && "${torch_build}" != cuda ]]; then
  echo "install.sh: CPHYSFNO_TORCH='${torch_build}' is neither 'cpu' nor 'cuda'" >&2
  exit 2
fi

dry_run=0
if [[ -n "${CPHYSFNO_INSTALL_DRY_RUN:-}" && "${CPHYSFNO_INSTALL_DRY_RUN}" != 0 ]]; then
  dry_run=1
  echo "dry run: the commands are printed, not run"
fi

# Print the command; run it unless this is a dry run.
run() {
  printf '+'
  printf ' %q' "$@"
  printf '\n'
  if [[ "${dry_run}" == 0 ]]; then "$@"; fi
}

# Succeed when the index answers within 5 s (name lookup included).
index_answers() {
  python3 - "$1" <<'EOF'
import os, ssl, sys, threading, urllib.request

url = sys.argv[1].rstrip("/") + "/torch/"
cafile = os.environ.get("PIP_CERT") or None
answered = []

def probe():
    try:
        context = ssl.create_default_context(cafile=cafile)
        with urllib.request.urlopen(url, timeout=5, context=context):
            answered.append(True)
    except Exception:
        pass

thread = threading.Thread(target=probe, daemon=True)
thread.start()
thread.join(5)
sys.exit(0 if answered else 1)
EOF
}

# "VERSION BUILD" of the torch that imports in .venv (BUILD: cpu, cuda or rocm), or nothing.
installed_torch() {
  [[ -x .venv/bin/python ]] || return 0
  .venv/bin/python -c '
import torch
build = "cuda" if torch.version.cuda else "rocm" if getattr(torch.version, "hip", None) else "cpu"
print(torch.__version__, build)' 2>/dev/null || true
}

run python3 -m venv .venv
pip=(./.venv/bin/python -m pip)
run "${pip[@]}" install --quiet --upgrade pip

read -r have_version have_build <<<"$(installed_torch)" || true
keep=0
if [[ "${have_version:-}" == "${TORCH_VERSION}" || "${have_version:-}" == "${TORCH_VERSION}+"* ]]; then
  if [[ "${torch_build}" == cpu || "${have_build}" != cpu ]]; then keep=1; fi
fi
if [[ "${keep}" == 1 ]]; then
  echo "torch: keeping torch ${have_version} (${have_build} build) already in .venv"
else
  index=()
  if [[ "${torch_build}" == cuda ]]; then
    echo "torch: the default build from the configured package index (CUDA on Linux from PyPI)"
  elif index_answers "${CPU_INDEX}"; then
    echo "torch: the CPU build from ${CPU_INDEX}"
    index=(--index-url "${CPU_INDEX}")
  else
    echo "torch: ${CPU_INDEX} did not answer within 5 s; torch==${TORCH_VERSION} from the" \
      "configured package index instead (on Linux, PyPI's is the CUDA build)"
  fi
  if [[ "${torch_build}" == cuda && "${have_build:-}" == cpu ]]; then
    # Otherwise pip takes the installed CPU build as satisfying torch==VERSION.
    run "${pip[@]}" uninstall --yes --quiet torch
  fi
  run "${pip[@]}" install --quiet "torch==${TORCH_VERSION}" ${index[@]+"${index[@]}"}
  if [[ "${dry_run}" == 0 ]]; then
    read -r have_version have_build <<<"$(installed_torch)" || true
    echo "torch: installed torch ${have_version:-?} (${have_build:-?} build)"
    if [[ "${torch_build}" == cuda && "${have_build:-}" == cpu ]]; then
      echo "torch: warning: --cuda asked for a CUDA build but the package index gave a CPU one" >&2
    fi
  fi
fi

extra=""
if [[ "${dev}" == 1 ]]; then extra="[dev]"; fi
args=(-e ".${extra}")
optional=("plugins/cphysfno-neuralop/")  # neuraloperator pulls wandb and tensorly (~90 MB)
for plugin in plugins/*/; do
  [[ -f "${plugin}pyproject.toml" ]] || continue
  if [[ "${dev}" == 0 && " ${optional[*]} " == *" ${plugin} "* ]]; then continue; fi
  args+=(-e "${plugin}")
done
run "${pip[@]}" install --quiet "${args[@]}"
if [[ "${dry_run}" == 1 ]]; then
  echo "dry run: nothing was installed"
else
  echo "cphysfno installed in .venv: run .venv/bin/cphysfno --help"
fi
