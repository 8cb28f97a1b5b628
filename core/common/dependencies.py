"""The Python packages the plugin needs, which are present, and how to install them (no QGIS, no Qt here).

pycolmap and OpenCV are not part of QGIS.  The plugin installs the pinned wheels with QGIS's own Python
into a folder it owns inside the QGIS profile (``<profile>/python/dependencies/archaeoortho/py3.X``, one
folder per Python version so a QGIS upgrade never loads wheels built for another Python), never into
QGIS's install folder, and puts that folder on ``sys.path`` when it loads (:func:`activate`).

Rules that keep a working machine working:

- the folder goes on ``sys.path`` only when an install into it has succeeded (the user chose it); a machine
  whose site-packages already holds a pycolmap never sees the folder otherwise;
- pip runs with ``--no-deps``: it never installs a NumPy next to QGIS's (a NumPy 2 there would break GDAL's
  bindings on a NumPy 1 QGIS); :func:`unmet_requirements` checks the wheels' own requirements (NumPy's
  version) against what QGIS has;
- wheels only (``--only-binary=:all:``): no compiler is ever needed, and a platform without wheels fails
  at once with pip's message.
"""
from __future__ import annotations

import importlib
import importlib.metadata
import importlib.util
import ntpath
import os
import platform as _platform
import posixpath
import re
import shlex
import subprocess
import sys
from dataclasses import dataclass
from typing import Callable, Iterable, List, Optional, Sequence, Tuple


@dataclass(frozen=True)
class Requirement:
    """One package: its import name, PyPI name, the pinned (tested) version and the versions that work."""

    module: str
    dist: str
    version: str
    label: str
    minimum: str  # the oldest version the plugin works with
    below: str  # the first version it is known not to work with (the next major release)

    @property
    def pin(self) -> str:
        return f"{self.dist}=={self.version}"


# requirements.txt pins the same versions (tests/test_dependencies.py checks)
REQUIREMENTS: Tuple[Requirement, ...] = (
    Requirement("pycolmap", "pycolmap", "4.2.1", "pycolmap (alignment)", "4.2", "5"),
    Requirement("cv2", "opencv-python-headless", "4.10.0.84", "OpenCV (image processing)", "4.5", "5"),
)

# optional packages: the plugin loads and runs without them; the one feature that needs one names it and the pip
# command when used.  rvt-py (relief visualisations, core/terrain/relief.py) is one pure-Python wheel whose
# metadata asks for Python < 3.12 and for jupyter, geopandas, rasterio, ... that rvt.vis never imports (it needs
# NumPy and SciPy only): it is installed with --no-deps --ignore-requires-python (tested on Python 3.11 and 3.13)
OPTIONAL: Tuple[Requirement, ...] = (
    Requirement("rvt", "rvt-py", "2.2.3", "rvt-py (relief visualisations)", "2.2", "3"),
    # quadric decimation of the 3-D model's mesh (core/model/geometry.py; without it a coarser grid meets the face
    # budget): wheels for Windows, macOS (arm64, x86-64) and Linux, Python 3.10-3.14; needs NumPy only
    Requirement("fast_simplification", "fast-simplification", "0.2.0", "fast-simplification (3-D model decimation)",
                "0.1", "1"),
)
OPTIONAL_PIP_FLAGS = ("--no-deps", "--ignore-requires-python")

# what `pip download --only-binary=:all: --platform <tag> --python-version <v> pycolmap==4.2.1` finds
# (checked for win_amd64, macosx_14_0_arm64, macosx_10_15_x86_64, macosx_13_0_x86_64, manylinux2014_x86_64,
# manylinux_2_28_x86_64/aarch64 and Python 3.10-3.14); OpenCV 4.10.0.84 has wheels everywhere pycolmap has
SUPPORTED = ("Ready-made packages exist for Python 3.10 to 3.14 on Windows (64-bit), macOS 14 or newer on "
             "Apple silicon, and Linux x86-64 (glibc 2.28 or newer). There are none for Intel Macs, Linux on "
             "ARM or 32-bit systems: there pycolmap has to be built from source.")
PYTHON_RANGE = ((3, 10), (3, 14))

_TARGET: Optional[str] = None  # the folder of this profile, once configure() ran (for the messages)


def _vtuple(version: str) -> Tuple[int, ...]:
    parts = []
    for piece in str(version).split("."):
        m = re.match(r"\d+", piece)
        if not m:
            break
        parts.append(int(m.group()))
    return tuple(parts)


# ---------------------------------------------------------------- the plugin-owned folder on sys.path

def python_tag(version_info: Sequence[int] = tuple(sys.version_info[:2])) -> str:
    return f"py{version_info[0]}.{version_info[1]}"


def target_dir(profile_dir: str, tag: Optional[str] = None) -> str:
    """The plugin-owned folder that pip installs into, inside the QGIS profile folder ``profile_dir``."""
    return os.path.join(os.path.abspath(profile_dir), "python", "dependencies", "archaeoortho",
                        tag or python_tag())


def installed_here(target: str, requirements: Iterable[Requirement] = REQUIREMENTS) -> List[str]:
    """The PyPI names of ``requirements`` that an install put into ``target`` (their .dist-info is there)."""
    if not os.path.isdir(target):
        return []
    names = {_dist_name(n) for n in os.listdir(target) if n.endswith(".dist-info")}
    return [r.dist for r in requirements if _norm(r.dist) in names]


def _norm(name: str) -> str:
    return re.sub(r"[-_.]+", "_", name).lower()


def _dist_name(dist_info: str) -> str:
    """'opencv_python_headless-4.10.0.84.dist-info' -> 'opencv_python_headless'."""
    return _norm(dist_info[:-len(".dist-info")].rsplit("-", 1)[0])


def configure(profile_dir: str) -> str:
    """Remember this profile's folder (the messages name it) and return it; sys.path is left alone."""
    global _TARGET
    _TARGET = target_dir(profile_dir)
    return _TARGET


def activate(profile_dir: str, path: Optional[List[str]] = None,
             requirements: Iterable[Requirement] = REQUIREMENTS) -> Optional[str]:
    """At plugin load: configure(), and put the folder first on ``sys.path`` if an install into it
    succeeded (so the user's choice wins over an older copy in site-packages).  Returns the folder put on
    the path, else None: without an install nothing changes, so a working pycolmap is never shadowed."""
    target = configure(profile_dir)
    path = sys.path if path is None else path
    if not installed_here(target, requirements):
        return None
    if target in path:
        path.remove(target)
    path.insert(0, target)
    importlib.invalidate_caches()
    return target


def configured_target() -> Optional[str]:
    return _TARGET


# ---------------------------------------------------------------- what is present

@dataclass
class Found:
    """What this Python has of one requirement.  ``state`` is ok / untested / missing / unsupported."""

    requirement: Requirement
    version: Optional[str] = None  # None: not importable
    location: str = ""

    @property
    def state(self) -> str:
        r = self.requirement
        if self.location == "":
            return "missing"
        if self.version is None:
            return "untested"  # present, version unknown (a distribution package without metadata)
        v = _vtuple(self.version)
        if v < _vtuple(r.minimum) or v >= _vtuple(r.below):
            return "unsupported"
        return "ok" if v[:3] == _vtuple(r.version)[:3] else "untested"  # cv2.__version__ is 4.10.0

    @property
    def usable(self) -> bool:
        return self.state in ("ok", "untested")

    def describe(self) -> str:
        r = self.requirement
        state = self.state
        if state == "missing":
            return f"{r.label}: not installed (needs {r.pin})"
        if state == "unsupported":
            return (f"{r.label}: version {self.version} in {self.location} does not work with ArchaeoOrtho "
                    f"(needs {r.minimum} or newer, below {r.below}; tested with {r.version})")
        if state == "untested":
            return f"{r.label}: {self.version or 'unknown version'} in {self.location} (tested with {r.version})"
        return f"{r.label}: {self.version} in {self.location}"


def _version_in(site: str, module: str) -> Optional[str]:
    """The version of the distribution in folder ``site`` that installed top-level ``module``."""
    try:
        names = os.listdir(site)
    except OSError:
        return None
    for name in names:
        if not name.endswith(".dist-info"):
            continue
        dist = importlib.metadata.PathDistribution(_Path(os.path.join(site, name)))
        top = (dist.read_text("top_level.txt") or "").split()
        files = dist.files or []
        if module in top or any(str(f).split("/")[0].split(".")[0] == module for f in files):
            return dist.version
    return None


def _Path(p):  # noqa: N802 - pathlib lazily (keeps this module's import light)
    import pathlib

    return pathlib.Path(p)


def probe(requirement: Requirement) -> Found:
    """Where ``requirement`` would be imported from and its version, WITHOUT importing it (a broken
    package must not take QGIS down at start): the import machinery's spec and the .dist-info next to it."""
    module = sys.modules.get(requirement.module)
    if module is not None:
        version = getattr(module, "__version__", None)
        where = os.path.dirname(os.path.dirname(getattr(module, "__file__", "") or "")) or "?"
        return Found(requirement, str(version) if version else None, where)
    try:
        spec = importlib.util.find_spec(requirement.module)
    except (ImportError, ValueError):
        spec = None
    if spec is None or not spec.origin:
        return Found(requirement)
    origin = spec.origin
    package_dir = (list(spec.submodule_search_locations)[0] if spec.submodule_search_locations
                   else origin)
    site = os.path.dirname(os.path.abspath(package_dir))
    return Found(requirement, _version_in(site, requirement.module), site)


def check(requirements: Iterable[Requirement] = REQUIREMENTS) -> List[Found]:
    importlib.invalidate_caches()
    return [probe(r) for r in requirements]


def problems(found: Iterable[Found]) -> List[Found]:
    return [f for f in found if not f.usable]


# ---------------------------------------------------------------- platform, python, the pip command

def unsupported_platform(platform: str = sys.platform, machine: Optional[str] = None,
                         version: Sequence[int] = tuple(sys.version_info[:2]),
                         mac_release: Optional[str] = None, glibc: Optional[str] = None) -> Optional[str]:
    """Why no wheel of the pinned pycolmap fits this machine, or None when one does."""
    machine = (machine if machine is not None else _platform.machine()).lower()
    if not PYTHON_RANGE[0] <= tuple(version[:2]) <= PYTHON_RANGE[1]:
        return f"there are no pycolmap wheels for Python {version[0]}.{version[1]}"
    if platform.startswith("win"):
        return None if machine in ("amd64", "x86_64") else f"there are no pycolmap wheels for Windows on {machine}"
    if platform == "darwin":
        if machine != "arm64":
            return "there are no pycolmap wheels for Intel Macs (only Apple silicon, macOS 14 or newer)"
        release = mac_release if mac_release is not None else _platform.mac_ver()[0]
        if release and _vtuple(release) < (14,):
            return f"the pycolmap wheels need macOS 14 or newer (this is {release})"
        return None
    if platform.startswith("linux"):
        if machine not in ("x86_64", "amd64"):
            return f"there are no pycolmap wheels for Linux on {machine}"
        libc = glibc if glibc is not None else _platform.libc_ver()[1]
        if libc and _vtuple(libc) < (2, 28):
            return f"the pycolmap wheels need glibc 2.28 or newer (this system has {libc})"
        return None
    return f"there are no pycolmap wheels for {platform}"


def find_python(executable: Optional[str] = None, exec_prefix: Optional[str] = None,
                platform: str = sys.platform, version: Sequence[int] = tuple(sys.version_info[:2]),
                exists: Callable[[str], bool] = os.path.exists) -> str:
    """The Python interpreter of this QGIS, to run pip with.  Inside QGIS ``sys.executable`` is QGIS itself
    on Windows and macOS: there it is ``python.exe`` in ``sys.exec_prefix`` (OSGeo4W, the standalone
    installer) or the bundle's ``bin/python3``; on Linux the distribution's python3."""
    executable = sys.executable if executable is None else executable
    exec_prefix = sys.exec_prefix if exec_prefix is None else exec_prefix
    paths = ntpath if platform.startswith("win") else posixpath
    join = paths.join
    if (re.match(r"python[\d.]*(\.exe)?$", paths.basename(executable or "").lower())
            and _inside(executable, exec_prefix, paths)):
        return executable  # a real interpreter of this installation (not QGIS, not another python3 on PATH)
    major_minor = f"{version[0]}.{version[1]}"
    here = paths.dirname(executable or "")
    if platform.startswith("win"):
        candidates = [join(exec_prefix, "python.exe"), join(exec_prefix, "python3.exe"), join(here, "python.exe")]
    elif platform == "darwin":
        candidates = [join(here, "bin", "python3"), join(exec_prefix, "bin", f"python{major_minor}"),
                      join(exec_prefix, "bin", "python3")]
    else:
        candidates = [join(exec_prefix, "bin", f"python{major_minor}"), join(exec_prefix, "bin", "python3"),
                      f"/usr/bin/python{major_minor}", "/usr/bin/python3"]
    for c in candidates:
        if exists(c):
            return c
    return candidates[0]


def _inside(path: str, prefix: str, paths) -> bool:
    """True when ``path`` lies in ``prefix`` (an embedded Python sets sys.executable to whatever 'python3' is
    first on PATH, e.g. a pyenv shim: that is another Python, whose pip would install for the wrong one)."""
    path, prefix = paths.normcase(paths.abspath(path)), paths.normcase(paths.abspath(prefix))
    return path.startswith(prefix.rstrip(paths.sep) + paths.sep)


def pip_arguments(target: str, requirements: Iterable[Requirement] = REQUIREMENTS,
                  find_links: Optional[str] = None, no_index: bool = False) -> List[str]:
    """The arguments after the python executable: pip installs the pinned wheels, and nothing else (no
    NumPy), into ``target``."""
    args = ["-m", "pip", "install", "--upgrade", "--no-deps", "--only-binary=:all:", "--target", target]
    if find_links:
        args += ["--find-links", find_links]
    if no_index:
        args.append("--no-index")
    return args + [r.pin for r in requirements]


def pip_environment(environ: Optional[dict] = None) -> dict:
    """The environment pip runs in: QGIS's own, with a non-interactive pip that prints no progress bars."""
    env = dict(os.environ if environ is None else environ)
    env.update({"PIP_DISABLE_PIP_VERSION_CHECK": "1", "PIP_NO_INPUT": "1", "PIP_PROGRESS_BAR": "off",
                "PYTHONUNBUFFERED": "1", "PYTHONNOUSERSITE": "1"})
    return env


def command_line(program: str, args: Sequence[str], platform: str = sys.platform) -> str:
    """One line to paste into a terminal (cmd.exe / the OSGeo4W Shell on Windows, a POSIX shell elsewhere)."""
    if platform.startswith("win"):
        return subprocess.list2cmdline([program, *args])
    return shlex.join([program, *args])


def install_command(packages: Optional[Iterable[str]] = None) -> str:
    """The command a user runs for a missing package: the plugin folder's pip command for the pinned
    packages once configure() knows the profile, else the plain pip command."""
    optional = [r for r in OPTIONAL if packages is not None and (r.dist in packages or r.module in packages)]
    if optional:
        return command_line("python3", ["-m", "pip", "install", *OPTIONAL_PIP_FLAGS, *[r.pin for r in optional]])
    wanted = [r for r in REQUIREMENTS if packages is None or r.dist in packages or r.module in packages]
    known = {r.dist for r in REQUIREMENTS} | {r.module for r in REQUIREMENTS}
    others = [p for p in (packages or []) if p not in known]
    if others or not wanted:
        return command_line("python3", ["-m", "pip", "install", *(others or [r.pin for r in REQUIREMENTS])])
    if _TARGET is None:
        return command_line("python3", ["-m", "pip", "install", *[r.pin for r in REQUIREMENTS]])
    return command_line(find_python(), pip_arguments(_TARGET))


# ---------------------------------------------------------------- after the install

VERIFY_SCRIPT = """
import importlib, os, sys
target = sys.argv[1]
sys.path.insert(0, target)
import numpy
print("numpy", numpy.__version__, os.path.dirname(numpy.__file__))
for name in sys.argv[2:]:
    m = importlib.import_module(name)
    print(name, getattr(m, "__version__", "?"), os.path.dirname(m.__file__))
    if not os.path.abspath(m.__file__).startswith(os.path.abspath(target)):
        sys.exit(name + " was imported from " + m.__file__ + ", not from " + target)
if os.path.abspath(numpy.__file__).startswith(os.path.abspath(target)):
    sys.exit("a NumPy was installed into " + target + ": it must not be")
"""


def verify_arguments(target: str, requirements: Iterable[Requirement] = REQUIREMENTS) -> List[str]:
    """Arguments after the python executable that import each package from ``target`` (in a fresh process,
    with QGIS's NumPy) and fail with the reason if one does not load."""
    return ["-c", VERIFY_SCRIPT, target, *[r.module for r in requirements]]


def _markers():
    try:
        from packaging.requirements import Requirement as PkgRequirement
    except ImportError:  # pragma: no cover - pip vendors packaging
        try:
            from pip._vendor.packaging.requirements import Requirement as PkgRequirement
        except ImportError:
            return None
    return PkgRequirement


def _installed_version(dist: str) -> Optional[str]:
    try:
        return importlib.metadata.version(dist)
    except importlib.metadata.PackageNotFoundError:
        try:
            return str(importlib.import_module(dist).__version__)
        except Exception:  # noqa: BLE001 - not importable: not installed
            return None


def unmet_requirements(target: str, requirements: Iterable[Requirement] = REQUIREMENTS,
                       installed: Callable[[str], Optional[str]] = _installed_version) -> List[str]:
    """What the wheels in ``target`` need (their Requires-Dist, e.g. a NumPy version) that this Python lacks:
    pip ran with --no-deps, so QGIS's own packages must satisfy them."""
    pkg_requirement = _markers()
    if pkg_requirement is None or not os.path.isdir(target):
        return []
    wanted = {_norm(r.dist) for r in requirements}
    unmet = []
    for name in sorted(os.listdir(target)):
        if not name.endswith(".dist-info") or _dist_name(name) not in wanted:
            continue
        dist = importlib.metadata.PathDistribution(_Path(os.path.join(target, name)))
        for line in dist.requires or []:
            req = pkg_requirement(line)
            if req.marker is not None and not req.marker.evaluate({"extra": ""}):
                continue
            have = installed(req.name)
            if have is None:
                unmet.append(f"{dist.metadata['Name']} needs {req}, which is not installed")
            elif req.specifier and not req.specifier.contains(have, prereleases=True):
                unmet.append(f"{dist.metadata['Name']} needs {req}; this QGIS has {req.name} {have}")
    return unmet
