"""The core's own messages in the user's language (issue 48 item 6).

The core (no Qt) writes its progress lines, log lines and the adjustment's diagnosis in English, most of them
f-strings with numbers and names in them.  i18n/make_catalog.py collects their templates (each f-string's fields
as ``{}``) into qgisio/core_messages.py, context ``CoreMessages``; ``translate_message`` finds the template a
message was made from, translates it and puts the message's own values back in:
"mapping: registered image {}" -> "Zuordnung: Bild {} registriert".  A message made from no known template, or
from one without a finished translation, stays as it is."""
import re
import string

from qgis.core import QgsApplication
from qgis.PyQt.QtCore import QCoreApplication, QLocale, QSettings

from .core_messages import TEMPLATES

CONTEXT = "CoreMessages"
_PATTERNS = []  # (pattern, template), the templates with the most fixed text first


def _patterns():
    if not _PATTERNS:
        compiled = []
        for template in TEMPLATES:
            parts = list(string.Formatter().parse(template))
            regex = "".join(re.escape(text) + ("(.+?)" if field is not None else "") for text, field, _s, _c in parts)
            fixed = sum(len(text) for text, *_ in parts)
            compiled.append((fixed, re.compile(regex + r"\Z", re.DOTALL), template))
        _PATTERNS.extend((p, t) for _f, p, t in sorted(compiled, key=lambda c: -c[0]))
    return _PATTERNS


def translate_message(message):
    """``message`` (one of the core's, possibly several lines) in the language of QGIS's translator."""
    if not message or not isinstance(message, str):
        return message
    if "\n" in message:
        return "\n".join(translate_message(line) for line in message.split("\n"))
    exact = QCoreApplication.translate(CONTEXT, message)
    if exact != message:
        return exact
    for pattern, template in _patterns():
        m = pattern.match(message)
        if m is None:
            continue
        translated = QCoreApplication.translate(CONTEXT, template)
        if translated == template:
            return message
        try:
            return translated.format(*m.groups())
        except (IndexError, KeyError, ValueError):  # a translation whose fields do not fit: the English
            return message
    return message


def qgis_language() -> str:
    """The two-letter language QGIS runs in, read the way QGIS applies it (call it when the plugin is set up,
    not at import): the override of Options > General (``locale/overrideFlag`` + ``locale/userLocale``), else
    the translation QGIS installed at start (``qgis --lang de`` sets it, QgsApplication.translation()), else (no
    QGIS desktop: qgis_process, a script) QgsApplication.locale(), the system's language.  A ``locale/userLocale``
    that ``qgis --lang`` left in the profile does not switch later headless runs.  The plugin's translator and
    the report's language (ReportOptions.language) follow it."""
    settings = QSettings()
    override = str(settings.value("locale/overrideFlag", False)).lower() in ("true", "1")
    value = str(settings.value("locale/userLocale", "") or "") if override else ""
    if not value:
        try:
            app = QgsApplication.instance()
            value = app.translation() if isinstance(app, QgsApplication) else ""
        except Exception:  # noqa: BLE001 - no QgsApplication yet
            value = ""
    if not value:
        try:
            value = QgsApplication.locale()
        except Exception:  # noqa: BLE001 - no QgsApplication yet
            value = ""
    return str(value or QLocale.system().name())[:2]


def report_language() -> str:
    """QGIS's language for ReportOptions.language: a two-letter code, "" where QGIS runs in none (the "C"
    locale of a bare system)."""
    lang = qgis_language().lower()
    return lang if re.fullmatch("[a-z]{2}", lang) else ""
