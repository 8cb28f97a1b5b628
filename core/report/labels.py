"""The report's headings and figure labels in the user's language (issue 48 item 6).

The core has no Qt: the translations are read from the plugin's own Qt Linguist files
(``i18n/archaeoortho_<language>.ts``, context ``Report``), which ``make transup`` fills from the ``t("...")`` calls
of core/report (i18n/make_catalog.py collects them).  ``t(text)`` gives the translation of the language set for the
report being written (``with language("de"):``), the text itself in English or where no translation is finished.
Figures with numbers are translated as templates: ``t("mean {} px").format(value)``."""
from __future__ import annotations

import contextlib
import os
import xml.etree.ElementTree as ET
from contextvars import ContextVar
from typing import Dict, Iterator, Tuple

CONTEXT = "Report"
I18N = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))), "i18n")
_LABELS: ContextVar[Tuple[str, Dict[str, str]]] = ContextVar("report_labels", default=("", {}))


def t(text: str) -> str:
    """``text`` in the report's language."""
    return _LABELS.get()[1].get(text, text)


def current_language() -> str:
    """The language code of the report being written ("en" for English, or where no translation was found)."""
    lang, labels = _LABELS.get()
    return lang if labels else "en"


def load(lang: str) -> Dict[str, str]:
    """{English: translation} of the finished ``Report`` messages of ``i18n/archaeoortho_<lang>.ts``; {} for
    English or a language without a file."""
    path = os.path.join(I18N, f"archaeoortho_{lang}.ts")
    if not lang or lang == "en" or not os.path.exists(path):
        return {}
    out = {}
    for ctx in ET.parse(path).getroot().iter("context"):
        if ctx.findtext("name") != CONTEXT:
            continue
        for msg in ctx.iter("message"):
            tr = msg.find("translation")
            if tr is not None and tr.text and tr.get("type") not in ("unfinished", "obsolete", "vanished"):
                out[msg.findtext("source")] = tr.text
    return out


@contextlib.contextmanager
def language(lang: str) -> Iterator[None]:
    """``t`` translates into ``lang`` ("de", "it"; "" or "en": English) inside the block."""
    token = _LABELS.set((lang, load(lang)))
    try:
        yield
    finally:
        _LABELS.reset(token)
