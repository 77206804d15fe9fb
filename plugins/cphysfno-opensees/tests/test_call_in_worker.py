"""One function run in a worker process: its result, its errors, its process's death."""

from __future__ import annotations

import importlib
import sys
import textwrap

import pytest
from cphysfno_opensees.runner import call_in_worker

from cphysfno_core import ConfigError, PluginError

TASKS = '''
"""Tasks for the worker tests (a module, so that the workers can import them)."""

import os
import signal

from cphysfno_core import ConfigError


def add(a, b):
    return a + b, os.getpid()


def refuses(name):
    raise ConfigError(f"{name} is not a model")


def buggy():
    return undefined_name  # noqa: F821


def exits():
    os._exit(255)  # as OpenSees does on some errors


def crashes():
    os.kill(os.getpid(), signal.SIGSEGV)
'''


@pytest.fixture(scope="module")
def tasks(tmp_path_factory):
    folder = tmp_path_factory.mktemp("tasks")
    (folder / "worker_call_tasks.py").write_text(textwrap.dedent(TASKS))
    sys.path.insert(0, str(folder))
    try:
        yield importlib.import_module("worker_call_tasks")
    finally:
        sys.path.remove(str(folder))
        sys.modules.pop("worker_call_tasks", None)


def test_the_result_comes_back_from_another_process(tasks):
    total, pid = call_in_worker(tasks.add, 2, 3)
    assert total == 5
    assert pid != __import__("os").getpid()


def test_a_package_error_is_raised_as_it_was(tasks):
    with pytest.raises(ConfigError, match="frame.py is not a model"):
        call_in_worker(tasks.refuses, "frame.py")


def test_another_exception_is_a_plugin_error_with_its_traceback(tasks):
    with pytest.raises(PluginError, match="probing raised:\n(.|\n)*NameError"):
        call_in_worker(tasks.buggy, description="probing")


@pytest.mark.parametrize(("task", "cause"), [("exits", "exit code 255"), ("crashes", "SIGSEGV")])
def test_a_process_that_ends_without_answering_is_a_plugin_error(tasks, task, cause):
    with pytest.raises(PluginError, match=f"probing: the OpenSees worker process died .*{cause}"):
        call_in_worker(getattr(tasks, task), description="probing")
