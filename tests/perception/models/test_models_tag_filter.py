"""Tag filter: reply parsing, and a fake OpenAI-compatible server with timeouts, malformed replies, retries."""

from __future__ import annotations

import json

import pytest

from react3d_core.errors import StageError
from react3d_models.tag_filter import CachedTagFilter, chat_asker, chat_url, parse_reply

TAGS = ["cabinet", "chair", "door", "drawer", "table"]


def _ok(content: str) -> bytes:
    return json.dumps({"choices": [{"message": {"role": "assistant", "content": content}}]}).encode()


def test_parse_reply_variants():
    assert parse_reply('Sure! ["Cabinet", "drawer", "lamp"]', TAGS) == ["cabinet", "drawer"]
    assert parse_reply("- cabinet\n- drawer\n", TAGS) == ["cabinet", "drawer"]
    assert parse_reply("cabinet, drawer", TAGS) == ["cabinet", "drawer"]
    assert parse_reply("[]", TAGS) == []
    assert parse_reply("none", TAGS) == []
    assert parse_reply("I cannot help with that.", TAGS) is None
    assert chat_url("http://h:1/v1/") == "http://h:1/v1/chat/completions"


def _filter(url: str, timeout: float = 2.0, retries: int = 2) -> CachedTagFilter:
    ask = chat_asker(url + "/v1", "llava", timeout_s=timeout, retries=retries, backoff_s=0.01)
    return CachedTagFilter(ask, always_keep=("door",), retries=retries, backoff_s=0.01)


def test_keeps_openable_and_door_and_caches(fake_server):
    srv = fake_server(lambda i, body: (200, _ok('["cabinet", "drawer"]'), 0))
    f = _filter(srv.url)
    assert f.filter(TAGS) == ["cabinet", "door", "drawer"]
    req = srv.requests[0]
    assert req["path"] == "/v1/chat/completions" and req["body"]["model"] == "llava"
    assert "door" not in req["body"]["messages"][1]["content"].split("\n- ")  # door is never asked about
    assert f.filter(["cabinet", "table"]) == ["cabinet"]
    assert len(srv.requests) == 1  # both already decided


def test_malformed_reply_is_retried(fake_server):
    replies = [(200, b"not json at all", 0), (200, _ok("I am not sure."), 0), (200, _ok('["drawer"]'), 0)]
    srv = fake_server(lambda i, body: replies[min(i, 2)])
    assert _filter(srv.url).filter(TAGS) == ["door", "drawer"]
    assert len(srv.requests) == 3


def test_timeout_and_server_error_are_retried(fake_server):
    replies = [(200, _ok('["cabinet"]'), 1.5), (503, b"busy", 0), (200, _ok('["cabinet"]'), 0)]
    srv = fake_server(lambda i, body: replies[min(i, 2)])
    assert _filter(srv.url, timeout=0.3).filter(TAGS) == ["cabinet", "door"]
    assert len(srv.requests) == 3


def test_unreadable_answers_fall_back_to_door_only(fake_server):
    srv = fake_server(lambda i, body: (200, _ok("Hmm."), 0))
    assert _filter(srv.url, retries=1).filter(TAGS) == ["door"]
    assert len(srv.requests) == 2


def test_dead_endpoint_raises_one_line_error(fake_server):
    srv = fake_server(lambda i, body: (500, b"boom", 0))
    with pytest.raises(StageError, match="failed after 2 attempts"):
        _filter(srv.url, retries=1).filter(TAGS)
    srv2 = fake_server(lambda i, body: (401, b"no", 0))
    with pytest.raises(StageError, match="HTTP 401"):
        _filter(srv2.url).filter(TAGS)
    assert len(srv2.requests) == 1
