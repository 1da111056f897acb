"""``earliest_word``: one alternation pattern gives what searching each name on its own gives."""
from __future__ import annotations

import re

from hypothesis import example, given, settings
from hypothesis import strategies as st

from camfab.design.materials import MATERIALS
from camfab.words import earliest_word

MATERIAL_WORDS = [w for m in MATERIALS.values() for w in (m.name, *m.aliases)]


def one_by_one(text: str, words: list[str]) -> int | None:
    """The rule as stated, name by name: the earliest match as a word; ties to the first name."""
    best: tuple[int, int] | None = None
    for i, word in enumerate(words):
        m = re.search(rf"(?<![\w.-]){re.escape(word)}(?![\w.-])", text, re.IGNORECASE)
        if m and (best is None or m.start() < best[0]):
            best = (m.start(), i)
    return None if best is None else best[1]


pieces = st.sampled_from([*MATERIAL_WORDS, " ", ", ", "-", ".", "_", "x", "N", "steel", "(", ")", "é", "İ", "ß",
                          "\n", "*", "+", "[", "\\"])
words = st.lists(st.text(alphabet="aAcC45-. *+()[]\\^$|?İß", min_size=0, max_size=5), min_size=1, max_size=8)


@settings(max_examples=400, deadline=None)
@given(st.lists(pieces, max_size=12).map("".join))
@example("C45N and C45")
@example("EN AW-6082 T6")
@example("grey cast iron gg-25")
def test_material_names_as_each_name_alone(text):
    assert earliest_word(text, MATERIAL_WORDS) == one_by_one(text, MATERIAL_WORDS)


@settings(max_examples=400, deadline=None)
@given(st.lists(pieces | st.text(alphabet="aAcC45-. *+()", max_size=3), max_size=10).map("".join), words)
@example("c45", ["C4", "c45", "C45"])
@example("ab", ["", "ab"])
def test_any_names_as_each_name_alone(text, names):
    """Regex metacharacters, prefixes of one another, repeated and empty names, case and non-ASCII letters."""
    assert earliest_word(text, names) == one_by_one(text, names)


def test_many_names_and_none():
    names = [f"alloy{i}" for i in range(1000)]
    assert earliest_word("an alloy999 cam, alloy5", names) == 999
    assert earliest_word("anything", []) is None
    assert earliest_word("C45N", ["C45"]) is None
