"""install.sh's choices, checked in its dry run on a copy of the script: nothing is installed.

The CPU index is a local HTTP server (reachable) or a closed port (unreachable), so the
tests need no network.
"""

from __future__ import annotations

import functools
import http.server
import os
import shutil
import socket
import stat
import subprocess
import threading
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).parents[1]
SCRIPT = ROOT / "install.sh"
TORCH = "torch==2.13.0"


@pytest.fixture(scope="module")
def cpu_index(tmp_path_factory):
    """The URL of a local index that answers for torch."""
    folder = tmp_path_factory.mktemp("index")
    (folder / "whl" / "cpu" / "torch").mkdir(parents=True)
    (folder / "whl" / "cpu" / "torch" / "index.html").write_text("<html></html>")

    class Quiet(http.server.SimpleHTTPRequestHandler):
        def log_message(self, *args):
            pass

    server = http.server.ThreadingHTTPServer(
        ("127.0.0.1", 0), functools.partial(Quiet, directory=str(folder))
    )
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    yield f"http://127.0.0.1:{server.server_address[1]}/whl/cpu"
    server.shutdown()
    server.server_close()


def closed_port_url() -> str:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        port = sock.getsockname()[1]
    return f"http://127.0.0.1:{port}/whl/cpu"


@pytest.fixture
def project(tmp_path):
    """A copy of install.sh beside a core pyproject and two plugins, one of them optional."""
    shutil.copy(SCRIPT, tmp_path / "install.sh")
    (tmp_path / "pyproject.toml").write_text("[project]\nname = 'x'\n")
    for name in ("cphysfno-alpha", "cphysfno-neuralop"):
        (tmp_path / "plugins" / name).mkdir(parents=True)
        (tmp_path / "plugins" / name / "pyproject.toml").write_text("[project]\n")
    return tmp_path


def fake_torch(project: Path, version: str, build: str) -> None:
    """A .venv/bin/python that answers install.sh's question about the installed torch."""
    python = project / ".venv" / "bin" / "python"
    python.parent.mkdir(parents=True)
    python.write_text(f"#!/bin/sh\necho '{version} {build}'\n")
    python.chmod(python.stat().st_mode | stat.S_IXUSR)


def install(project: Path, *args: str, index: str, **env: str) -> subprocess.CompletedProcess:
    clean = {k: v for k, v in os.environ.items() if not k.startswith("CPHYSFNO_")}
    clean.update(CPHYSFNO_INSTALL_DRY_RUN="1", CPHYSFNO_TORCH_CPU_INDEX=index, **env)
    return subprocess.run(
        ["bash", str(project / "install.sh"), *args],
        capture_output=True,
        text=True,
        env=clean,
        timeout=60,
    )


def commands(result: subprocess.CompletedProcess) -> list[str]:
    assert result.returncode == 0, result.stderr
    return [line[2:] for line in result.stdout.splitlines() if line.startswith("+ ")]


def torch_command(result: subprocess.CompletedProcess) -> str:
    [line] = [c for c in commands(result) if f" install --quiet {TORCH}" in c]
    return line


def test_the_script_parses():
    result = subprocess.run(["bash", "-n", str(SCRIPT)], capture_output=True, text=True)
    assert result.returncode == 0, result.stderr


def test_default_is_the_cpu_build_from_the_cpu_index(project, cpu_index):
    result = install(project, index=cpu_index)
    assert torch_command(result).endswith(f"{TORCH} --index-url {cpu_index}")
    assert f"torch: the CPU build from {cpu_index}" in result.stdout
    # Torch comes before the core and the plugins, which would otherwise pull a bare torch.
    steps = commands(result)
    assert steps.index(torch_command(result)) < len(steps) - 1
    assert " -e ." in steps[-1]


def test_the_cpu_index_is_the_default_url():
    text = SCRIPT.read_text()
    assert 'CPU_INDEX="${CPHYSFNO_TORCH_CPU_INDEX:-https://download.pytorch.org/whl/cpu}"' in text


@pytest.mark.parametrize(
    ("args", "env"),
    [(("--cuda",), {}), ((), {"CPHYSFNO_TORCH": "cuda"}), (("--dev", "--cuda"), {})],
)
def test_the_cuda_switch_drops_the_cpu_index(project, cpu_index, args, env):
    result = install(project, *args, index=cpu_index, **env)
    assert torch_command(result).endswith(TORCH)
    assert "--index-url" not in result.stdout
    assert "default build from the configured package index" in result.stdout


def test_cpu_flag_overrides_the_environment(project, cpu_index):
    result = install(project, "--cpu", index=cpu_index, CPHYSFNO_TORCH="cuda")
    assert torch_command(result).endswith(f"--index-url {cpu_index}")


def test_unreachable_cpu_index_falls_back_to_the_plain_requirement(project):
    url = closed_port_url()
    start = time.monotonic()
    result = install(project, index=url)
    assert time.monotonic() - start < 30
    assert torch_command(result).endswith(TORCH)
    assert f"torch: {url} did not answer within 5 s" in result.stdout


def test_unknown_flag_fails_listing_the_options(project, cpu_index):
    result = install(project, "--gpu", index=cpu_index)
    assert result.returncode == 2
    assert "unknown option '--gpu'" in result.stderr
    for option in ("--dev", "--cuda", "--cpu", "--help"):
        assert option in result.stderr
    assert "+ " not in result.stdout


def test_unknown_torch_build_in_the_environment_fails(project, cpu_index):
    result = install(project, index=cpu_index, CPHYSFNO_TORCH="rocm")
    assert result.returncode == 2
    assert "CPHYSFNO_TORCH='rocm'" in result.stderr and "'cuda'" in result.stderr


def test_help_documents_the_switches(project, cpu_index):
    result = install(project, "--help", index=cpu_index)
    assert result.returncode == 0
    for word in ("--dev", "--cuda", "CPHYSFNO_TORCH=cpu|cuda", "CPHYSFNO_INSTALL_DRY_RUN=1"):
        assert word in result.stdout
    assert "+ " not in result.stdout


def test_dev_adds_the_dev_extras_and_the_optional_plugins(project, cpu_index):
    runtime = commands(install(project, index=cpu_index))[-1]
    dev = commands(install(project, "--dev", index=cpu_index))[-1]
    assert runtime.endswith("install --quiet -e . -e plugins/cphysfno-alpha/")
    assert "-e .\\[dev\\]" in dev  # printed shell-quoted
    assert "-e plugins/cphysfno-alpha/" in dev and "-e plugins/cphysfno-neuralop/" in dev


def test_dry_run_creates_nothing(project, cpu_index):
    before = sorted(p.relative_to(project) for p in project.rglob("*"))
    result = install(project, "--dev", index=cpu_index)
    assert result.returncode == 0, result.stderr
    assert "dry run: nothing was installed" in result.stdout
    assert sorted(p.relative_to(project) for p in project.rglob("*")) == before


@pytest.mark.parametrize(
    ("installed", "args"),
    [
        (("2.13.0+cpu", "cpu"), ()),
        (("2.13.0", "cuda"), ()),
        (("2.13.0+cu128", "cuda"), ("--cuda",)),
    ],
)
def test_a_suitable_installed_torch_is_kept(project, cpu_index, installed, args):
    fake_torch(project, *installed)
    result = install(project, *args, index=cpu_index)
    assert f"keeping torch {installed[0]}" in result.stdout
    assert not [c for c in commands(result) if "torch" in c]


def test_cuda_replaces_an_installed_cpu_build(project, cpu_index):
    fake_torch(project, "2.13.0+cpu", "cpu")
    result = install(project, "--cuda", index=cpu_index)
    steps = commands(result)
    uninstall = steps.index("./.venv/bin/python -m pip uninstall --yes --quiet torch")
    assert uninstall < steps.index(torch_command(result))


def test_another_torch_version_is_replaced(project, cpu_index):
    fake_torch(project, "2.12.1+cpu", "cpu")
    result = install(project, index=cpu_index)
    assert torch_command(result).endswith(f"--index-url {cpu_index}")
    assert "keeping" not in result.stdout
