"""fabricate.export.svg's escape and quoteattr: the text of xml.sax.saxutils' (which the build no longer imports)."""

from __future__ import annotations

import itertools
from xml.sax.saxutils import escape as sax_escape
from xml.sax.saxutils import quoteattr as sax_quoteattr

from fabricate.export.svg import escape, quoteattr


def test_escape_and_quoteattr_give_saxutils_text_for_every_short_string():
    alphabet = 'a<>&"\'\n\r\té'
    for n in range(4):
        for chars in itertools.product(alphabet, repeat=n):
            text = "".join(chars)
            assert escape(text) == sax_escape(text), text
            assert quoteattr(text) == sax_quoteattr(text), text
