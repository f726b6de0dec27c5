"""``key_names`` (what a completion lists) against the uses of every key (``key_uses``):
the same keys, each with the form of its first use, the one under the cursor left out."""

from __future__ import annotations

from hypothesis import given, settings
from hypothesis import strategies as st

from bt_lsp.ide.blackboard import KeyForm, key_names, key_uses
from bt_lsp.syntax.document import Document
from bt_lsp.syntax.elements import Zone

_KEYS = st.sampled_from(["a", "b", "goal", "x_1", "@a"])
_SCRIPTS = st.lists(
    st.tuples(_KEYS, st.sampled_from([":=1", " == 2", "+=b", ":='{q}'", " &amp;&amp; b"])),
    max_size=4,
).map(lambda parts: "; ".join(k + op for k, op in parts))
_NODES = st.one_of(
    _SCRIPTS.map(lambda c: f'<Script code="{c}"/>'),
    _SCRIPTS.map(lambda c: f'<AlwaysSuccess _skipIf="{c}"/>'),
    _KEYS.map(lambda k: f'<MoveBase goal="{{{k.lstrip("@")}}}" speed="{{=}}" v="="/>'),
    _SCRIPTS.map(lambda c: f'<Precondition if="{c}" else="FAILURE"><Frob/></Precondition>'),
    st.just('<Sleep msec="{ a }"/>'),
)


def _old(doc: Document, tree: int, at: int) -> dict[str, KeyForm]:
    out: dict[str, KeyForm] = {}
    for k in key_uses(doc, tree):
        if not k.start <= at <= k.end:
            out.setdefault(k.key, k.form)
    return out


@settings(max_examples=150, deadline=None)
@given(st.lists(_NODES, min_size=1, max_size=6), st.data())
def test_key_names_are_the_keys_of_the_uses(nodes: list[str], data: st.DataObject) -> None:
    text = (
        '<root BTCPP_format="4"><BehaviorTree ID="T"><Sequence>'
        + "".join(nodes)
        + "</Sequence></BehaviorTree></root>"
    )
    doc = Document(text)
    tree = next(i for i, el in enumerate(doc.model.elements) if el.zone == Zone.TREE)
    at = data.draw(st.integers(-1, len(text)))
    got = key_names(doc, tree, at)
    assert list(got.items()) == list(_old(doc, tree, at).items())
