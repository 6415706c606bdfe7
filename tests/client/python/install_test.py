"""`pip install ./client/python` as a user would run it: a venv that sees
Debian's grpcio, protobuf and numpy (--system-site-packages), pip with no
index (nothing may come from the network: the build backend generates the
stubs with protoc itself), then the client's unit tests and the example
against a live fovea-server, all importing the installed package (no
PYTHONPATH). Exits 77 (ctest SKIP_RETURN_CODE) when venv, pip or the
modules are missing.

    install_test.py --source_dir . --server_binary build/bin/fovea-server \\
        --models_dir models
"""

import argparse
import os
import pathlib
import subprocess
import sys
import tempfile
import unittest

ARGS = None  # set in __main__


def run(command, env, timeout=600):
    result = subprocess.run(command, capture_output=True, text=True,
                            timeout=timeout, env=env)
    sys.stdout.write(result.stdout[-4000:])
    sys.stderr.write(result.stderr[-4000:])
    return result


class InstallTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        venv = pathlib.Path(cls.tmp.name) / "venv"
        made = subprocess.run([sys.executable, "-m", "venv",
                               "--system-site-packages", str(venv)],
                              capture_output=True, text=True)
        if made.returncode != 0:
            raise unittest.SkipTest(f"no venv: {made.stderr.strip()}")
        cls.python = str(venv / "bin" / "python")
        # Nothing of this checkout on the path: what runs is what pip
        # installed.
        cls.env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
        cls.env["PYTHONDONTWRITEBYTECODE"] = "1"
        cls.env["PIP_NO_INDEX"] = "1"
        cls.env["PIP_DISABLE_PIP_VERSION_CHECK"] = "1"
        cls.source = pathlib.Path(ARGS.source_dir)
        cls.installed = run([cls.python, "-m", "pip", "install", "--no-cache-dir",
                             str(cls.source / "client" / "python")], cls.env)

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def test_1_pip_installs_it_with_generated_stubs(self):
        self.assertEqual(self.installed.returncode, 0, self.installed.stderr)
        where = run([self.python, "-c",
                     "import fovea_client, fovea.v1.segment_pb2 as s, "
                     "fovea.health.v1.health_pb2 as h; "
                     "print(fovea_client.__file__); print(s.__file__); "
                     "print(h.__file__); "
                     "print(s.ObjectResult.DESCRIPTOR.fields_by_name"
                     "['oriented_box'].number)"], self.env)
        self.assertEqual(where.returncode, 0, where.stderr)
        lines = where.stdout.split()
        for path in lines[:3]:
            self.assertIn(self.tmp.name, path)  # the venv's, not the tree's
        self.assertEqual(lines[3], "10")
        typed = pathlib.Path(lines[0]).parent / "py.typed"
        self.assertTrue(typed.exists(), "the package says it is typed")

    def test_2_unit_tests_pass_against_the_installed_package(self):
        for name in ("channel", "frame", "geometry", "rle"):
            script = self.source / "tests" / "client" / "python" / f"{name}_test.py"
            result = run([self.python, str(script)], self.env)
            self.assertEqual(result.returncode, 0, f"{name}: {result.stderr}")

    def test_3_example_runs_against_a_server(self):
        script = self.source / "tests" / "client" / "python" / "example_test.py"
        result = run([self.python, str(script),
                      "--server_binary", ARGS.server_binary,
                      "--models_dir", ARGS.models_dir,
                      "--example",
                      str(self.source / "client" / "python" / "example.py")],
                     self.env)
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertIn("box on the support", result.stdout + result.stderr)


if __name__ == "__main__":
    parser = argparse.ArgumentParser()
    parser.add_argument("--source_dir", required=True)
    parser.add_argument("--server_binary", required=True)
    parser.add_argument("--models_dir", required=True)
    ARGS, rest = parser.parse_known_args()
    if subprocess.run([sys.executable, "-c", "import venv, ensurepip"],
                      capture_output=True).returncode != 0:
        print("skipped: python3-venv is not installed")
        sys.exit(77)
    unittest.main(argv=[sys.argv[0]] + rest)
