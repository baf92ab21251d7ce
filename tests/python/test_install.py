"""`pip install` of the checkout into a fresh virtual environment, as a user
installs the package (pyproject.toml, setup.py), then every example of
examples/python run from another folder against the installed package.

Debian's setuptools, NumPy and pip, offline: the venv sees the system's
packages (--system-site-packages) and pip gets --no-index
--no-build-isolation, so the declared dependency on NumPy is met by
python3-numpy, not fetched. The extension comes from the CMake build tree
ctest runs in (APPELL_BUILD_DIR: `cmake --build --target appell_python`,
nothing to rebuild), so the test adds no compilation to a CI run.
"""

import os
import pathlib
import shutil
import subprocess
import time

import pytest

from conftest import SOURCE_DIR


def _copy_source(dest):
    # A copy, so that pip's and setuptools' build files stay out of the checkout.
    ignore = shutil.ignore_patterns("build*", ".git", "node_modules", "__pycache__", "*.egg-info", ".pip-*")
    shutil.copytree(SOURCE_DIR, dest, ignore=ignore)


def test_pip_install_into_a_venv_then_the_examples_run_from_elsewhere(tmp_path):
    build_dir = os.environ.get("APPELL_BUILD_DIR")
    if not build_dir:
        pytest.skip("APPELL_BUILD_DIR (set by ctest) names the build tree to take the extension from")
    src, venv, elsewhere = tmp_path / "src", tmp_path / "venv", tmp_path / "elsewhere"
    _copy_source(src)
    elsewhere.mkdir()
    subprocess.run(["/usr/bin/python3", "-m", "venv", "--system-site-packages", str(venv)], check=True)
    python = venv / "bin" / "python"
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PIP_FIND_LINKS")}
    env["APPELL_BUILD_DIR"] = build_dir
    start = time.perf_counter()
    pip = subprocess.run([str(python), "-m", "pip", "install", "--no-index", "--no-build-isolation", str(src)],
                         env=env, cwd=elsewhere, capture_output=True, text=True)
    seconds = time.perf_counter() - start
    assert pip.returncode == 0, pip.stdout + pip.stderr
    assert "Successfully installed appell-0.1.0" in pip.stdout, pip.stdout
    print(f"pip install took {seconds:.1f} s")

    # The installed package is the one imported (not the build tree's), with
    # its compiled extension and its NumPy arrays.
    probe = subprocess.run([str(python), "-c", "import appell, appell._appell as x, numpy; "
                            "print(appell.__file__); print(x.__file__); print(numpy.__version__)"],
                           env=env, cwd=elsewhere, capture_output=True, text=True)
    assert probe.returncode == 0, probe.stderr
    package, extension, _ = probe.stdout.splitlines()
    assert pathlib.Path(package).resolve().is_relative_to(venv.resolve()), package
    assert pathlib.Path(extension).resolve().is_relative_to(venv.resolve()), extension

    examples = sorted((SOURCE_DIR / "examples" / "python").glob("*.py"))
    assert examples, "examples/python has no example"
    for example in examples:
        r = subprocess.run([str(python), str(example)], env=env, cwd=elsewhere, capture_output=True, text=True,
                           timeout=600)
        assert r.returncode == 0, f"{example.name}:\n{r.stdout}\n{r.stderr}"
