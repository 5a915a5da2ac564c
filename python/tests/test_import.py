"""`import mfr` under a Python the extension was not built for says which one it was built for
(the README's PYTHONPATH=build/python python3, where python3 is another interpreter)."""

import os
import shutil
import subprocess
import sys

import mfr


def test_another_python_is_named_with_the_one_the_module_was_built_for(tmp_path):
    package = os.path.dirname(mfr.__file__)
    copy = tmp_path / "mfr"
    # the package as another interpreter sees it: no extension module for its version
    shutil.copytree(package, copy, ignore=shutil.ignore_patterns("_mfr*", "__pycache__"))
    (copy / "_built_for.py").write_text('INTERPRETER = "/opt/python3.99/bin/python3"\n'
                                        'VERSION = "3.99"\n')
    proc = subprocess.run([sys.executable, "-c", "import mfr"], capture_output=True, text=True,
                          env={**os.environ, "PYTHONPATH": str(tmp_path)})
    assert proc.returncode != 0
    last = proc.stderr.strip().splitlines()[-1]
    running = f"{sys.version_info[0]}.{sys.version_info[1]}"
    assert last == (f"ImportError: mfr: the extension module was built for Python 3.99 "
                    f"(/opt/python3.99/bin/python3), not this Python {running} "
                    f"({sys.executable}): run /opt/python3.99/bin/python3, or rebuild with "
                    f"-DPython3_EXECUTABLE={sys.executable}"), proc.stderr
    # the same version: the import's own error, not a wrong diagnosis
    (copy / "_built_for.py").write_text(f'INTERPRETER = "x"\nVERSION = "{running}"\n')
    proc = subprocess.run([sys.executable, "-c", "import mfr"], capture_output=True, text=True,
                          env={**os.environ, "PYTHONPATH": str(tmp_path)})
    assert proc.returncode != 0 and "_mfr" in proc.stderr and "built for" not in proc.stderr


def test_the_build_records_this_interpreter():
    from mfr import _built_for
    assert _built_for.VERSION == f"{sys.version_info[0]}.{sys.version_info[1]}"
    assert os.path.realpath(_built_for.INTERPRETER) == os.path.realpath(sys.executable)
