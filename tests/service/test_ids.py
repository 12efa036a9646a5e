"""service.ids: content addresses of fits."""

from service.ids import content_address, content_id


def test_content_id():
    assert content_id("a", b"b") == content_id("a", b"b")
    assert content_id("a", b"b") != content_id("ab", b"")
    assert len(content_id("x")) == 32


def test_ids_from_an_unambiguous_encoding():
    assert content_address("a\x00b", "c") != content_address("a", "b\x00c")
    assert content_address("ab", "c") != content_address("a", "bc")
    assert content_address(b"\x00", "") != content_address("", b"\x00")
    assert content_address(1.0) != content_address(1) and content_address([1.5]) == content_address([1.5])
