"""
Small hostile inputs, as classes against a real ``python -m service``
on 127.0.0.1 (a fresh corpus, seeded): integers past 64 bits in queries,
``Host`` values with junk after the name, request headers past 16 KiB,
repeated form parts, malformed multipart (422, as the docs say), and
framing headers on every page; plus the store's free-space floor and a
full temporary directory (507).
"""

from __future__ import annotations

import os
import random

import loopback
import pytest

from conftest import app_client, server_process

API = "/api/v1"
SEED = 20261220
GOOD_CSV = b"wavelength_nm,n,k\n400,0.2,3\n500,0.2,3.2\n600,0.2,3.4\n700,0.2,3.6\n800,0.2,3.8\n"


@pytest.fixture(scope="module")
def server(tmp_path_factory):
    with server_process(tmp_path_factory.mktemp("small") / "data", COATED_WARM_POOL="false") as running:
        with loopback.Client(base_url=running.url, timeout=30) as http:
            yield running, http


def assert_clear_4xx(response, status, pattern):
    assert response.status_code == status, (response.status_code, response.text[:300])
    assert response.headers["content-type"].startswith("application/json")
    assert pattern.lower() in response.json()["detail"].lower(), response.text[:300]


@pytest.mark.slow
@pytest.mark.server
class TestSmallOnesByClass:
    def test_integers_past_64_bits_in_queries_are_422(self, server):
        _, http = server
        rng = random.Random(SEED)
        values = [2**63, 2**63 + rng.randint(1, 10**6), 10 ** rng.randint(19, 40), 2**64 - 1]
        for value in values:
            for query in ("cursor", "limit"):
                assert_clear_4xx(http.get(f"{API}/materials", params={query: str(value)}), 422, query)
        assert http.get(f"{API}/materials", params={"cursor": str(2**63 - 1)}).status_code == 200

    def test_host_with_junk_after_the_name_is_refused(self, server):
        running, http = server
        rng = random.Random(SEED + 1)
        junk = ["evil.example", ".evil.example", "x", ":80x", ":", ":123456", "]", "@evil.example"]
        hosts = [f"[::1]{rng.choice(junk)}" for _ in range(6)]
        hosts += [f"localhost:{p}" for p in ("80x", "", "8000.evil.example", "-1")]
        hosts += ["127.0.0.1:99999999", f"127.0.0.1:{running.port}evil"]
        for host in sorted(set(hosts)):
            assert_clear_4xx(http.get("/healthz", headers={"Host": host}), 400, "`Host`")
        for host in (f"[::1]:{running.port}", "[::1]", f"localhost:{running.port}", "127.0.0.1"):
            assert http.get("/healthz", headers={"Host": host}).status_code == 200, host

    def test_headers_past_16_kib_are_431(self, server):
        running, http = server
        rng = random.Random(SEED + 2)
        for size in [16_500, rng.randint(17_000, 60_000), 100_000, 300_000]:
            many = rng.random() < 0.5
            headers = {f"x-h{i}": "v" * 990 for i in range(size // 1000)} if many else {"x-big": "v" * size}
            response = loopback.get(f"{running.url}/healthz", headers=headers, timeout=30)
            assert response.status_code == 431, (size, many, response.status_code)
            assert "16384 bytes" in response.json()["detail"]
        assert http.get("/healthz", headers={"x-ok": "v" * 12_000}).status_code == 200

    def test_repeated_form_parts_are_refused(self, server):
        _, http = server
        for count in (2, 3):
            files = [("file", (f"a{i}.csv", GOOD_CSV, "text/csv")) for i in range(count)]
            assert_clear_4xx(http.post(f"{API}/fits/upload", files=files), 422, f"got {count} `file` parts")
        files = [("file", ("a.csv", GOOD_CSV, "text/csv"))]
        response = http.post(f"{API}/fits/upload", files=files, data={"name": ["a", "b"]})
        assert_clear_4xx(response, 422, "`name` parts")

    def test_malformed_multipart_is_422(self, server):
        _, http = server
        rng = random.Random(SEED + 3)
        boundary = "b" + "".join(rng.choice("abc0123") for _ in range(20))
        shapes = {
            "no boundary": ("multipart/form-data", b"--x\r\n\r\n"),
            "too many fields": (
                f"multipart/form-data; boundary={boundary}",
                b"".join(
                    f'--{boundary}\r\nContent-Disposition: form-data; name="f{i}"\r\n\r\nv\r\n'.encode()
                    for i in range(1_200)
                )
                + f"--{boundary}--\r\n".encode(),
            ),
        }
        for label, (ctype, data) in shapes.items():
            response = http.post(f"{API}/fits/upload", content=data, headers={"content-type": ctype})
            assert response.status_code == 422, (label, response.status_code, response.text[:200])

    def test_every_page_forbids_framing(self, server):
        _, http = server
        for path in ("/", "/docs", "/openapi.json", f"{API}/materials", "/no-such-page", "/healthz"):
            response = http.get(path)
            assert response.headers.get("x-frame-options") == "DENY", path
            assert "frame-ancestors 'none'" in response.headers.get("content-security-policy", ""), path
        refused = http.get("/healthz", headers={"Host": "evil.example"})
        assert refused.status_code == 400 and refused.headers.get("x-frame-options") == "DENY"


@pytest.mark.slow  # starts a process (the guard in tests/conftest.py)
def test_a_full_disk_is_not_writable_even_with_no_reserve(tmp_path, monkeypatch):
    with app_client(tmp_path, store_min_free_bytes=0) as client:
        assert client.get("/healthz").json()["store_writable"] is True
        real = os.statvfs

        class Full:
            def __init__(self, stat):
                self.f_frsize, self.f_bavail = stat.f_frsize, 0

        monkeypatch.setattr(os, "statvfs", lambda path: Full(real(path)))
        health = client.get("/healthz").json()
        assert health["store_writable"] is False and "bytes free" in health["store_problem"]
        response = client.post(f"{API}/fits", json={"material": "Au"})
        assert response.status_code == 507


@pytest.mark.slow  # 4.0 s in a --durations=0 run (an app's start and a 1.3 MB body)
def test_a_full_temporary_directory_is_507_not_the_file_s_fault(tmp_path, monkeypatch):
    """
    An upload past Starlette's 1 MiB spool goes to a temporary file; on a
    full disk its write fails with ENOSPC, which FastAPI reported as an
    unparsable body (422 blaming the file). The disk is made full here by
    the temporary file's creation failing as the kernel's would.
    """
    import errno
    import tempfile

    def full(*args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device")

    body = GOOD_CSV + b"".join(b"800,0.2,3.8\n" for _ in range(110_000))  # 1.3 MB: spooled to disk
    with app_client(tmp_path) as client:
        monkeypatch.setattr(tempfile, "TemporaryFile", full)
        answer = client.post(f"{API}/fits/upload", files={"file": ("big.csv", body, "text/csv")})
    assert answer.status_code == 507 and "temporary directory is full" in answer.json()["detail"], answer.text
    assert answer.headers["retry-after"] == "60"
