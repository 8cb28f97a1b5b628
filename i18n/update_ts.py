"""Update the .ts files from the sources (make transup): pylupdate5 on copies whose string escapes are decoded.

pylupdate5 does not decode Python escapes: ``self.tr("Open\\u2026")`` reaches the .ts file as "Openu2026",
a source text that the running code (which asks for "Open…") never looks up, so the string stays English.
This script copies the sources to a temporary tree with every ``\\uXXXX``, ``\\UXXXXXXXX``, ``\\xXX`` and
``\\N{NAME}`` escape inside a (non-raw) string literal replaced by its character, runs pylupdate5 there on
copies of the .ts files (same relative paths, so the <location> lines stay the same) and copies them back.

    python3 i18n/update_ts.py [pylupdate5 options]    # e.g. -noobsolete
    python3 i18n/update_ts.py --tracked -noobsolete   # only the files git tracks (leave others' new files out)
"""
import io
import os
import re
import shutil
import subprocess
import sys
import tempfile
import tokenize
import unicodedata

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SOURCE_GLOBS = ("", "processing_provider", "qgisio", "ui")  # *.py in these folders (as the Makefile's I18N_SOURCES)
TS_FILES = ("i18n/archaeoortho_de.ts", "i18n/archaeoortho_it.ts")

# an escape preceded by an even number of backslashes (so "\\u2026" - an escaped backslash - stays)
_ESCAPE = re.compile(r"(?<!\\)((?:\\\\)*)\\(u[0-9a-fA-F]{4}|U[0-9a-fA-F]{8}|x[0-9a-fA-F]{2}|N\{[^}]+\})")


def _char(match):
    code = match.group(2)
    char = unicodedata.lookup(code[2:-1]) if code[0] == "N" else chr(int(code[1:], 16))
    if char in "\"'\\" or not char.isprintable():  # a quote, a backslash, a control character: stays escaped
        return match.group(0)
    return match.group(1) + char


def decode_escapes(text):
    """``text`` (Python source) with the character escapes inside non-raw, non-bytes string literals decoded;
    everything else byte for byte the same (line numbers included)."""
    out = []
    starts = [0]  # offset of each line, as tokenize counts lines (split at "\n" only)
    for line in io.StringIO(text).readlines():
        starts.append(starts[-1] + len(line))

    def offset(pos):
        return starts[pos[0] - 1] + pos[1]

    pos_last = 0
    for tok in tokenize.generate_tokens(io.StringIO(text).readline):
        if tok.type != tokenize.STRING:
            continue
        prefix = re.match(r"[A-Za-z]*", tok.string).group(0).lower()
        if "r" in prefix or "b" in prefix:
            continue
        start, end = offset(tok.start), offset(tok.end)
        decoded = _ESCAPE.sub(_char, tok.string)
        if decoded != tok.string:
            out.append(text[pos_last:start])
            out.append(decoded)
            pos_last = end
    out.append(text[pos_last:])
    return "".join(out)


def sources(root=ROOT, tracked=False):
    known = None
    if tracked:
        out = subprocess.run(["git", "ls-files"], cwd=root, capture_output=True, text=True, check=True)
        known = set(out.stdout.split())
    for folder in SOURCE_GLOBS:
        base = os.path.join(root, folder)
        for name in sorted(os.listdir(base)):
            path = os.path.join(folder, name) if folder else name
            if name.endswith(".py") and (known is None or path in known):
                yield path


def main(argv):
    pylupdate = shutil.which("pylupdate5")
    if pylupdate is None:
        print("pylupdate5 not found (Debian: pyqt5-dev-tools)", file=sys.stderr)
        return 1
    tracked = "--tracked" in argv
    argv = [a for a in argv if a != "--tracked"]
    with tempfile.TemporaryDirectory(prefix="archaeoortho-ts-") as tmp:
        rel = list(sources(tracked=tracked))
        for path in rel:
            dst = os.path.join(tmp, path)
            os.makedirs(os.path.dirname(dst), exist_ok=True)
            with open(os.path.join(ROOT, path), encoding="utf-8") as f:
                text = f.read()
            with open(dst, "w", encoding="utf-8") as f:
                f.write(decode_escapes(text))
        os.makedirs(os.path.join(tmp, "i18n"), exist_ok=True)
        for ts in TS_FILES:
            if os.path.exists(os.path.join(ROOT, ts)):
                shutil.copyfile(os.path.join(ROOT, ts), os.path.join(tmp, ts))
        subprocess.run([pylupdate, *argv, *rel, "-ts", *TS_FILES], cwd=tmp, check=True)
        for ts in TS_FILES:
            shutil.copyfile(os.path.join(tmp, ts), os.path.join(ROOT, ts))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
