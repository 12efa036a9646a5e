"""service.ids: content addresses of fits."""

from service.ids import content_id


def test_content_id():
    assert content_id("a", b"b") == content_id("a", b"b")
    assert content_id("a", b"b") != content_id("ab", b"")
    assert len(content_id("x")) == 32
