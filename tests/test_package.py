"""The zip of ``make package`` against the rules of the official plugin repository (plugins.qgis.org's upload
validator, qgis/QGIS-Django qgis-app/plugins/validator.py): at most 25 MB, no path information, no .pyc,
__pycache__, .git or __MACOSX, one top folder named [A-Za-z][A-Za-z0-9-_]+ holding __init__.py, metadata.txt
with a [general] section and the mandatory fields, LICENSE, the icon, an author without slashes, real URLs.
(qgis-plugin-ci packages a plugin that lives in a sub-folder of its repository with ``git archive``; this
repository is the plugin itself, so it does not fit.)  The URLs are checked for form only (no network)."""
import configparser
import io
import os
import re
import shutil
import subprocess
import zipfile
from urllib.parse import urlparse

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MAX_SIZE = 25_000_000
REQUIRED = ("name", "description", "version", "qgisMinimumVersion", "author", "email", "about", "tracker",
            "repository")
PLACEHOLDER_URLS = {"tracker": "http://bugs", "repository": "http://repo", "homepage": "http://homepage"}


def validate_plugin_zip(path):
    """The list of problems the plugin repository would refuse ``path`` for (empty: accepted)."""
    problems = []
    if os.path.getsize(path) > MAX_SIZE:
        problems.append(f"{os.path.getsize(path)} bytes: more than {MAX_SIZE}")
    with zipfile.ZipFile(path) as z:
        names = z.namelist()
        for n in names:
            parts = n.split("/")
            if ".." in n or n.startswith("/"):
                problems.append(f"path information: {n}")
            if ".pyc" in n:
                problems.append(f".pyc file: {n}")
            problems += [f"{d} folder: {n}" for d in ("__MACOSX", ".git", "__pycache__") if d in parts]
        bad = z.testzip()
        if bad:
            problems.append(f"bad zip member: {bad}")
        tops = sorted({n.split("/")[0] for n in names})
        if len(tops) != 1:
            return problems + [f"not one top folder: {tops}"]
        top = tops[0]
        if not re.match(r"^[A-Za-z][A-Za-z0-9-_]+$", top):
            problems.append(f"top folder name {top!r}")
        for required in ("__init__.py", "metadata.txt", "LICENSE"):
            if f"{top}/{required}" not in names:
                problems.append(f"no {top}/{required}")
        if f"{top}/metadata.txt" not in names:
            return problems
        meta = configparser.ConfigParser(interpolation=None)
        meta.optionxform = str
        meta.read_file(io.StringIO(z.read(f"{top}/metadata.txt").decode("utf-8")))
        if not meta.has_section("general"):
            return problems + ["metadata.txt: no [general] section"]
        general = dict(meta.items("general"))
        problems += [f"metadata.txt: no {k}" for k in REQUIRED if not general.get(k, "").strip()]
        if "/" in general.get("author", ""):
            problems.append("metadata.txt: author with a slash")
        icon = general.get("icon", "").removeprefix("./")
        if icon and f"{top}/{icon}" not in names:
            problems.append(f"icon {icon} not in the zip")
        for key, placeholder in PLACEHOLDER_URLS.items():
            url = general.get(key)
            if url is None:
                continue
            parsed = urlparse(url)
            if url == placeholder or not (parsed.scheme and parsed.netloc):
                problems.append(f"metadata.txt: {key} is not a URL: {url!r}")
        qt6 = general.get("supportsQt6", "False").strip().lower() in ("true", "yes", "1")
        if general.get("qgisMaximumVersion", "3.99").startswith("4") and not qt6:
            problems.append("qgisMaximumVersion 4.x without supportsQt6=True")
    return problems


def test_the_validator_refuses_what_the_repository_refuses(tmp_path):
    good = tmp_path / "good.zip"
    meta = "[general]\n" + "".join(f"{k}=x\n" for k in REQUIRED if k not in ("tracker", "repository"))
    meta += "tracker=https://example.org/t\nrepository=https://example.org/r\nicon=icon.svg\n"
    with zipfile.ZipFile(good, "w") as z:
        for name, text in (("__init__.py", ""), ("metadata.txt", meta), ("LICENSE", "GPL"), ("icon.svg", "<svg/>")):
            z.writestr(f"plug/{name}", text)
    assert validate_plugin_zip(good) == []
    bad = tmp_path / "bad.zip"
    with zipfile.ZipFile(bad, "w") as z:
        z.writestr("plug/__init__.py", "")
        z.writestr("plug/__pycache__/x.cpython-311.pyc", "")
        z.writestr("plug/metadata.txt", meta.replace("email=x\n", "").replace("https://example.org/r", "repo")
                   + "qgisMaximumVersion=4.99\n")
        z.writestr("other/README", "")
    assert validate_plugin_zip(bad) == [
        ".pyc file: plug/__pycache__/x.cpython-311.pyc", "__pycache__ folder: plug/__pycache__/x.cpython-311.pyc",
        "not one top folder: ['other', 'plug']"]
    with zipfile.ZipFile(bad, "w") as z:
        z.writestr("plug/__init__.py", "")
        z.writestr("plug/metadata.txt", meta.replace("email=x\n", "").replace("https://example.org/r", "repo")
                   + "qgisMaximumVersion=4.99\n")
    assert validate_plugin_zip(bad) == ["no plug/LICENSE", "metadata.txt: no email", "icon icon.svg not in the zip",
                                        "metadata.txt: repository is not a URL: 'repo'",
                                        "qgisMaximumVersion 4.x without supportsQt6=True"]


def test_make_package_builds_a_zip_the_plugin_repository_accepts():
    if shutil.which("make") is None or shutil.which("zip") is None or shutil.which("lrelease") is None:
        pytest.skip("make / zip / lrelease not installed")
    res = subprocess.run(["make", "-s", "package"], cwd=ROOT, capture_output=True, text=True, timeout=600)
    assert res.returncode == 0, res.stdout + res.stderr
    path = os.path.join(ROOT, "dist", "archaeoortho.zip")
    assert validate_plugin_zip(path) == []
    with zipfile.ZipFile(path) as z:
        names = z.namelist()
    assert "archaeoortho/plugin.py" in names and "archaeoortho/processing_provider/provider.py" in names
    assert not any(n.startswith("archaeoortho/tests/") for n in names)
