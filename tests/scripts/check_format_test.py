"""scripts/check-format on small git repositories made in a temporary
folder: a badly formatted file changed since the base fails (exit 1) and is
named, with a fix command that fixes it, even with a space in its path;
files deleted since the base and files not changed are not checked; on
main the base is the previous commit. Skips without git or clang-format."""

import os
import shutil
import subprocess
import tempfile
import unittest
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
SCRIPT = ROOT / "scripts" / "check-format"

GOOD = "int Add(int a, int b) { return a + b; }\n"
BAD = "int  Add( int a,int b ){return a+b;}\n"

# No user configuration: a fixed identity, and `main` as the first branch.
GIT_ENV = {
    "GIT_CONFIG_GLOBAL": os.devnull,
    "GIT_CONFIG_NOSYSTEM": "1",
    "GIT_AUTHOR_NAME": "test",
    "GIT_AUTHOR_EMAIL": "test@example.com",
    "GIT_COMMITTER_NAME": "test",
    "GIT_COMMITTER_EMAIL": "test@example.com",
}


@unittest.skipUnless(shutil.which("git") and shutil.which("clang-format"),
                     "needs git and clang-format")
class CheckFormatTest(unittest.TestCase):
    def setUp(self):
        self._tmp = tempfile.TemporaryDirectory()
        self.repo = Path(self._tmp.name)
        self.env = {k: v for k, v in os.environ.items()
                    if k not in ("FOVEA_FORMAT_BASE", "CLANG_FORMAT")}
        self.env.update(GIT_ENV)
        self.git("init", "-q", "-b", "main")
        shutil.copy(ROOT / ".clang-format", self.repo / ".clang-format")
        self.write("core/add.cc", GOOD)
        self.write("core/old.h", GOOD)
        self.commit("start")

    def tearDown(self):
        self._tmp.cleanup()

    def git(self, *args):
        subprocess.run(["git", "-C", str(self.repo), *args], env=self.env,
                       check=True, capture_output=True)

    def write(self, path, text):
        (self.repo / path).parent.mkdir(parents=True, exist_ok=True)
        (self.repo / path).write_text(text)

    def commit(self, message):
        self.git("add", "-A")
        self.git("commit", "-q", "-m", message)

    def check(self, *args):
        result = subprocess.run(
            ["bash", str(SCRIPT), "--repo", str(self.repo), *args],
            env=self.env, capture_output=True, text=True, check=False)
        return result.returncode, result.stdout + result.stderr

    def test_badly_formatted_file_with_a_space_fails_and_the_fix_fixes_it(self):
        self.git("checkout", "-q", "-b", "topic")
        self.write("core/my file.cc", BAD)
        self.commit("bad")
        code, out = self.check()
        self.assertEqual(code, 1, out)
        self.assertIn("merge base with main", out)
        self.assertIn("not formatted: core/my file.cc", out)
        self.assertNotIn("core/add.cc", out)
        fix = [line for line in out.splitlines() if "clang-format -i" in line]
        self.assertEqual(len(fix), 1, out)
        subprocess.run(["bash", "-c", fix[0]], check=True)
        self.assertEqual((self.repo / "core/my file.cc").read_text(), GOOD)
        code, out = self.check()
        self.assertEqual(code, 0, out)
        self.assertIn("all 1 formatted", out)

    def test_no_cxx_change_passes(self):
        self.git("checkout", "-q", "-b", "topic")
        self.write("README.md", "words\n")
        self.commit("docs")
        code, out = self.check()
        self.assertEqual(code, 0, out)
        self.assertIn("no C++ files changed", out)

    def test_deleted_file_is_skipped(self):
        self.git("checkout", "-q", "-b", "topic")
        (self.repo / "core/old.h").unlink()
        self.write("core/new.h", GOOD)
        self.commit("delete old.h")
        code, out = self.check()
        self.assertEqual(code, 0, out)
        self.assertIn("1 C++ files changed", out)

    def test_uncommitted_edit_counts(self):
        self.write("core/add.cc", BAD)
        code, out = self.check("HEAD")
        self.assertEqual(code, 1, out)
        self.assertIn("not formatted: core/add.cc", out)

    def test_on_main_the_base_is_the_previous_commit(self):
        self.write("core/add.cc", BAD)
        self.commit("bad on main")
        code, out = self.check()
        self.assertEqual(code, 1, out)
        self.assertIn("(HEAD~1)", out)
        self.write("README.md", "words\n")
        self.commit("docs on main")
        code, out = self.check()
        self.assertEqual(code, 0, out)
        # An older base, from the environment, sees the bad commit again.
        self.env["FOVEA_FORMAT_BASE"] = "HEAD~2"
        code, out = self.check()
        self.assertEqual(code, 1, out)

    def test_unknown_base_cannot_check(self):
        code, out = self.check("no-such-commit")
        self.assertEqual(code, 2, out)
        self.assertIn("is not a commit", out)


if __name__ == "__main__":
    unittest.main()
