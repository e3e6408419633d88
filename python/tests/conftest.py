# Options ctest passes (python/CMakeLists.txt): the `vdyn` program to compare
# with, the source tree, and the test plugin library.
import json
import os
import subprocess

import pytest


def pytest_addoption(parser):
    parser.addoption("--vdyn-cli", required=True, help="the vdyn program of this build")
    parser.addoption("--vdyn-root", required=True, help="the source tree")
    parser.addoption("--vdyn-fixture", default="", help="tests/plugin_fixture/good.cpp's library")


@pytest.fixture(scope="session")
def cli(request):
    exe = request.config.getoption("--vdyn-cli")

    def run(*args, check=True):
        p = subprocess.run([exe, *args], capture_output=True, text=True)
        if check and p.returncode != 0:
            raise AssertionError(f"vdyn {' '.join(args)} failed ({p.returncode}): {p.stderr}")
        return p
    return run


@pytest.fixture(scope="session")
def root(request):
    return request.config.getoption("--vdyn-root")


@pytest.fixture(scope="session")
def fixture_library(request):
    return request.config.getoption("--vdyn-fixture")


def read_json(path):
    with open(path) as f:
        return json.load(f)
