"""Tests of scripts/freeze_build.sh on a stand-in build folder: it copies the programs and
libraries, and refuses while a build tool works in the folder (a copy taken mid-link mixes
old and new files)."""
import os
import shutil
import subprocess
import tempfile
import unittest
from pathlib import Path

FREEZE = Path(__file__).resolve().parents[2] / "scripts" / "freeze_build.sh"


class FreezeBuildTest(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        root = Path(self.tmp.name)
        self.build = root / "build"
        (self.build / "devel/lib/alvio").mkdir(parents=True)
        (self.build / "devel/lib/libalvio_core.so").write_text("core")
        for program in ("alvio_run", "alvio_sim"):
            (self.build / "devel/lib/alvio" / program).write_text(program)
        self.out = root / "frozen"

    def tearDown(self):
        self.tmp.cleanup()

    def freeze(self):
        env = dict(os.environ, ALVIO_BUILD_DIR=str(self.build))
        return subprocess.run(["bash", str(FREEZE), str(self.out)], env=env, capture_output=True,
                              text=True, timeout=60)

    def test_copies_programs_and_libraries(self):
        r = self.freeze()
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(r.stdout.strip(), str(self.out / "bin/alvio_run"))
        self.assertEqual((self.out / "lib/libalvio_core.so").read_text(), "core")
        self.assertEqual((self.out / "bin/alvio_sim").read_text(), "alvio_sim")

    def test_refuses_while_make_runs_in_the_build(self):
        # A process named make (sleep under that name) working in a subfolder of the build.
        tools = Path(self.tmp.name) / "tools"
        tools.mkdir()
        (tools / "make").symlink_to("/bin/sleep")
        workdir = self.build / "CMakeFiles"
        workdir.mkdir()
        make = subprocess.Popen([str(tools / "make"), "60"], cwd=workdir)
        try:
            r = self.freeze()
        finally:
            make.kill()
            make.wait()
        self.assertEqual(r.returncode, 1)
        self.assertIn(f"a build is running in {self.build} (pid {make.pid}, make)", r.stderr)
        self.assertFalse((self.out / "bin/alvio_run").exists())
        # Once the build is over, the same freeze goes through.
        self.assertEqual(self.freeze().returncode, 0)

    @unittest.skipUnless(shutil.which("gcc") and shutil.which("patchelf"), "needs gcc and patchelf")
    def test_frozen_program_loads_the_frozen_library(self):
        # A real program linked with its build's RUNPATH, as catkin links alvio_run: frozen, then
        # the build's library is rebuilt; run by hand without LD_LIBRARY_PATH, the frozen
        # program must still load the frozen library.
        lib = self.build / "devel/lib"
        src = Path(self.tmp.name) / "src"
        src.mkdir()

        def build_library(version):
            (src / "core.c").write_text(f"int core_version(void) {{ return {version}; }}\n")
            subprocess.run(["gcc", "-shared", "-fPIC", "-o", str(lib / "libalvio_core.so"),
                            str(src / "core.c")], check=True)

        build_library(1)
        (lib / "alvio/alvio_sim").touch()  # linked after the library, as make would
        (src / "run.c").write_text('#include <stdio.h>\nint core_version(void);\n'
                                   'int main(void) { printf("%d", core_version()); return 0; }\n')
        subprocess.run(["gcc", "-o", str(lib / "alvio/alvio_run"), str(src / "run.c"), f"-L{lib}",
                        "-lalvio_core", f"-Wl,-rpath,{lib}"], check=True)
        self.assertEqual(self.freeze().returncode, 0)
        build_library(2)
        env = {k: v for k, v in os.environ.items() if k != "LD_LIBRARY_PATH"}
        live = subprocess.run([str(lib / "alvio/alvio_run")], env=env, capture_output=True,
                              text=True)
        frozen = subprocess.run([str(self.out / "bin/alvio_run")], env=env, capture_output=True,
                                text=True)
        self.assertEqual(live.stdout, "2")
        self.assertEqual(frozen.stdout, "1", frozen.stderr)
        # The stand-in's other files (text, not programs) were copied as they were.
        self.assertEqual((self.out / "bin/alvio_sim").read_text(), "alvio_sim")

    def test_refuses_a_program_older_than_the_core_library(self):
        # Only the library and alvio_run rebuilt since alvio_sim was linked (make alvio_run).
        program = self.build / "devel/lib/alvio/alvio_sim"
        library = self.build / "devel/lib/libalvio_core.so"
        os.utime(program, (library.stat().st_mtime - 60, library.stat().st_mtime - 60))
        r = self.freeze()
        self.assertEqual(r.returncode, 1)
        self.assertIn(f"{program} is older than libalvio_core.so", r.stderr)
        self.assertFalse((self.out / "bin").exists())
        program.touch()
        self.assertEqual(self.freeze().returncode, 0)

    def test_missing_build_names_it(self):
        self.build = Path(self.tmp.name) / "nowhere"
        r = self.freeze()
        self.assertEqual(r.returncode, 1)
        self.assertIn(f"no build in {self.build}", r.stderr)


if __name__ == "__main__":
    unittest.main()
