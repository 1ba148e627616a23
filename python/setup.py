"""Builds the compiled core of `cadclash` with the project's CMake for `pip install ./python`.

The metadata is in pyproject.toml; this file only adds the extension. `build_ext` configures the
repository root (the directory above python/) with CADCLASH_BUILD_PYTHON=ON and everything else
off (tests, benchmarks, examples, tools, install rules, MPI), builds the single target `_cadclash`
for the interpreter that runs it (Python_EXECUTABLE=sys.executable) and copies the module into the
package, so the wheel holds cadclash/*.py, py.typed and _cadclash.<EXT_SUFFIX>.

Environment:
  CMAKE_BUILD_PARALLEL_LEVEL  compile jobs (default: one per core)
  CMAKE_ARGS                  extra CMake arguments, e.g. "-DCMAKE_CXX_COMPILER=clang++-14"
  CADCLASH_PYTHON_BUILD_DIR   the CMake build tree (default: python/build/temp.<platform>-<python>/cmake,
                              kept between installs so a rebuild compiles only what changed)
  CADCLASH_SOURCE_DIR         the repository root, when python/ is not inside it
  CADCLASH_NO_CCACHE=1        do not use ccache even when it is on PATH
ccache, when on PATH, is the compiler launcher (CMAKE_CXX_COMPILER_LAUNCHER=ccache) unless CMAKE_ARGS
names a launcher itself.
"""
import os
import shlex
import shutil
import subprocess
import sys
import sysconfig
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

HERE = Path(__file__).resolve().parent


class CMakeExtension(Extension):
    def __init__(self, name: str) -> None:
        super().__init__(name, sources=[])


def _source_dir() -> Path:
    root = Path(os.environ.get("CADCLASH_SOURCE_DIR") or HERE.parent).resolve()
    top = root / "CMakeLists.txt"
    if not top.is_file() or "project(cadclash" not in top.read_text(encoding="utf-8"):
        sys.exit(f"cadclash: {root} is not the cadclash repository root. `pip install ./python` builds "
                 "from a checkout (the C++ sources are above python/); set CADCLASH_SOURCE_DIR to the "
                 "repository root if python/ was copied elsewhere.")
    return root


class CMakeBuild(build_ext):
    def build_extension(self, ext: Extension) -> None:
        source = _source_dir()
        build = Path(os.environ.get("CADCLASH_PYTHON_BUILD_DIR") or Path(self.build_temp) / "cmake").resolve()
        build.mkdir(parents=True, exist_ok=True)
        user_args = shlex.split(os.environ.get("CMAKE_ARGS", ""))

        configure = ["cmake", "-S", str(source), "-B", str(build),
                     f"-DCMAKE_BUILD_TYPE={'Debug' if self.debug else 'Release'}",
                     f"-DPython_EXECUTABLE={sys.executable}",
                     "-DCADCLASH_BUILD_PYTHON=ON",
                     "-DCADCLASH_BUILD_TESTS=OFF", "-DCADCLASH_BUILD_BENCH=OFF",
                     "-DCADCLASH_BUILD_EXAMPLES=OFF", "-DCADCLASH_BUILD_TOOLS=OFF",
                     "-DCADCLASH_BUILD_FUZZERS=OFF", "-DCADCLASH_INSTALL=OFF", "-DCADCLASH_WITH_MPI=OFF"]
        # A new tree gets Ninja when it is there; an existing one keeps the generator it was made with.
        if not (build / "CMakeCache.txt").is_file() and shutil.which("ninja") and \
                not any(a.startswith("-G") for a in user_args):
            configure += ["-G", "Ninja"]
        if shutil.which("ccache") and os.environ.get("CADCLASH_NO_CCACHE") != "1" and \
                not any("COMPILER_LAUNCHER" in a for a in user_args):
            configure.append("-DCMAKE_CXX_COMPILER_LAUNCHER=ccache")
        configure += user_args
        self._run(configure)

        compile_ = ["cmake", "--build", str(build), "--target", "_cadclash"]
        if not os.environ.get("CMAKE_BUILD_PARALLEL_LEVEL"):  # when set, cmake --build reads it itself
            compile_ += ["--parallel", str(os.cpu_count() or 1)]
        self._run(compile_)

        name = "_cadclash" + sysconfig.get_config_var("EXT_SUFFIX")
        built = build / "python" / "cadclash" / name
        if not built.is_file():
            sys.exit(f"cadclash: the CMake build did not produce {built}")
        target = Path(self.get_ext_fullpath(ext.name))
        target.parent.mkdir(parents=True, exist_ok=True)
        self.copy_file(str(built), str(target))

    @staticmethod
    def _run(cmd: list) -> None:
        print("cadclash:", " ".join(shlex.quote(c) for c in cmd), flush=True)
        subprocess.run(cmd, check=True)


setup(ext_modules=[CMakeExtension("cadclash._cadclash")], cmdclass={"build_ext": CMakeBuild})
