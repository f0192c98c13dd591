"""Strategies for the values a person might write: sensible ones and absurd ones."""

from __future__ import annotations

import string

from hypothesis import strategies as st

ABSURD_NUMBERS = st.sampled_from(
    [0, -1, 5e-324, 1e308, -1e308, float("inf"), float("-inf"), float("nan"), 10**30, 10**400]
)
PLAIN_NUMBERS = st.one_of(
    st.integers(-1000, 1000), st.floats(-1e6, 1e6, allow_nan=False, allow_infinity=False)
)
ODD_TEXT = st.lists(
    st.one_of(
        st.sampled_from(list(string.printable)),
        st.sampled_from(
            ["\x1b[31m", "\u2028", "\x00", "é", "{", "}", "${x}", "{temperature_f:>9999}"]
        ),
    ),
    max_size=20,
).map("".join)
SCALARS = st.one_of(
    st.none(),
    st.booleans(),
    PLAIN_NUMBERS,
    ABSURD_NUMBERS,
    ODD_TEXT,
    st.sampled_from(["pink", "neck", "/sensors/touch/any", "/vars/x", "wave", "temperature"]),
)
VALUES = st.recursive(
    SCALARS,
    lambda inner: st.one_of(
        st.lists(inner, max_size=4),
        st.dictionaries(st.sampled_from(["a", "b", "key"]), inner, max_size=3),
    ),
    max_leaves=8,
)
