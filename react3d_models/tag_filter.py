"""Openable-tag filter (LLaVA in the paper): a language model keeps tags that have a part moving on a
revolute or prismatic joint. Two transports share one prompt and one tolerant reply parser:
any OpenAI-compatible chat endpoint (vLLM, Ollama, llama.cpp server; stdlib urllib, timeouts,
retries with exponential backoff) and a local ``transformers`` causal LM. Decisions are cached per
tag, so each tag is asked about once per worker. 'door' (config.always_keep_tags) is always kept.
"""

from __future__ import annotations

import json
import logging
import re
import time
import urllib.error
import urllib.request
from collections.abc import Callable, Sequence

import torch

from react3d_core.errors import StageError

from .runtime import Loaded

log = logging.getLogger(__name__)

SYSTEM_PROMPT = (
    "You classify object names from indoor scenes. An object is OPENABLE if it has a movable part "
    "actuated by a revolute joint (a door or lid that swings on a hinge) or a prismatic joint (a drawer "
    "or sliding door that slides along an axis). Examples: cabinet, wardrobe, drawer, refrigerator, oven, "
    "dishwasher, door are openable; table, chair, wall, floor, lamp, sofa, plant are not."
)


def filter_prompt(tags: Sequence[str]) -> str:
    """The user message: the candidate tags and the required reply format (a JSON list)."""
    return (
        "Which of these object names are openable?\n"
        + "\n".join(f"- {t}" for t in tags)
        + "\nAnswer with only a JSON list of the openable names, copied exactly, e.g. [\"cabinet\", \"drawer\"]. "
        "Answer [] if none is openable."
    )


def parse_reply(reply: str, tags: Sequence[str]) -> list[str] | None:
    """Tags named in a reply: a JSON list if there is one, else any quoted/listed names; None if unreadable.

    Only names that are among ``tags`` count (case-insensitive); anything else the model says is ignored.
    """
    by_lower = {t.lower().strip(): t for t in tags}
    m = re.search(r"\[[^\[\]]*\]", reply, flags=re.S)
    names: list[str] | None = None
    if m:
        try:
            val = json.loads(m.group(0))
            if isinstance(val, list):
                names = [str(v) for v in val]
        except json.JSONDecodeError:
            names = None
    if names is None:
        lines = [re.sub(r"^\s*(?:[-*\u2022]|\d+[.)])\s*", "", ln).strip(" \"'.,") for ln in re.split(r"[\n,]", reply)]
        names = [ln for ln in lines if ln.lower() in by_lower]
        if not names and reply.strip().lower() not in ("none", "[]", "none."):
            return None
    return sorted({by_lower[n.lower().strip()] for n in names if n.lower().strip() in by_lower})


class CachedTagFilter:
    """TagFilter over an ``ask(tags) -> reply`` function; unknown tags are asked once, answers cached."""

    def __init__(self, ask: Callable[[list[str]], str | None], always_keep: Sequence[str], retries: int, backoff_s: float) -> None:
        self.ask, self.always_keep = ask, tuple(always_keep)
        self.retries, self.backoff_s = retries, backoff_s
        self.known: dict[str, bool] = {}

    def _decide(self, unknown: list[str]) -> None:
        for attempt in range(self.retries + 1):
            reply = self.ask(unknown)
            kept = parse_reply(reply, unknown) if reply is not None else None
            if kept is not None:
                self.known.update({t: t in kept for t in unknown})
                return
            log.warning("tag filter: unreadable reply (attempt %d/%d): %r", attempt + 1, self.retries + 1, (reply or "")[:120])
            if attempt < self.retries:
                time.sleep(self.backoff_s * 2**attempt)
        log.warning("tag filter gave no readable answer for %d tags; keeping only %s", len(unknown), self.always_keep)
        self.known.update({t: False for t in unknown})

    def filter(self, tags: Sequence[str]) -> list[str]:
        tags = sorted({t.strip() for t in tags if t.strip()})
        unknown = [t for t in tags if t not in self.known and t not in self.always_keep]
        if unknown:
            self._decide(unknown)
        return [t for t in tags if t in self.always_keep or self.known.get(t, False)]


def chat_url(endpoint: str) -> str:
    """Base URL (…/v1) or full URL -> the chat-completions URL."""
    e = endpoint.rstrip("/")
    return e if e.endswith("/chat/completions") else e + "/chat/completions"


def chat_asker(endpoint: str, model: str, timeout_s: float, retries: int, backoff_s: float,
               api_key: str | None = None, max_tokens: int = 512) -> Callable[[list[str]], str | None]:
    """ask() for an OpenAI-compatible endpoint: retries transport errors/5xx/429 with backoff, then raises."""
    url = chat_url(endpoint)

    def ask(tags: list[str]) -> str | None:
        body = json.dumps({"model": model, "temperature": 0, "max_tokens": max_tokens, "messages": [
            {"role": "system", "content": SYSTEM_PROMPT}, {"role": "user", "content": filter_prompt(tags)}]}).encode()
        headers = {"Content-Type": "application/json"}
        if api_key:
            headers["Authorization"] = f"Bearer {api_key}"
        last: Exception | None = None
        for attempt in range(retries + 1):
            try:
                req = urllib.request.Request(url, data=body, headers=headers, method="POST")
                with urllib.request.urlopen(req, timeout=timeout_s) as resp:
                    raw = resp.read()
                try:
                    return str(json.loads(raw)["choices"][0]["message"]["content"])
                except (ValueError, KeyError, IndexError, TypeError):
                    return None  # malformed envelope: the caller retries the question
            except urllib.error.HTTPError as exc:
                last = exc
                if exc.code < 500 and exc.code != 429:
                    raise StageError(f"tag-filter endpoint {url} refused the request: HTTP {exc.code}") from None
            except (urllib.error.URLError, TimeoutError, ConnectionError) as exc:
                last = exc
            if attempt < retries:
                time.sleep(backoff_s * 2**attempt)
        raise StageError(f"tag-filter endpoint {url} failed after {retries + 1} attempts: {last}")

    return ask


def local_lm_asker(lm: Loaded, max_new_tokens: int) -> Callable[[list[str]], str | None]:
    """ask() through a local causal LM (chat template when the tokenizer has one), greedy decoding."""
    tok = lm.processor

    def ask(tags: list[str]) -> str | None:
        messages = [{"role": "system", "content": SYSTEM_PROMPT}, {"role": "user", "content": filter_prompt(tags)}]
        if getattr(tok, "chat_template", None):
            text = tok.apply_chat_template(messages, tokenize=False, add_generation_prompt=True)
        else:
            text = SYSTEM_PROMPT + "\n\n" + filter_prompt(tags) + "\nAnswer: "
        enc = tok(text=text, return_tensors="pt")
        ids, att = enc["input_ids"].to(lm.device), enc["attention_mask"].to(lm.device)
        inner = getattr(tok, "tokenizer", tok)
        pad = inner.pad_token_id if inner.pad_token_id is not None else inner.eos_token_id
        with torch.inference_mode():
            out = lm.model.generate(input_ids=ids, attention_mask=att, max_new_tokens=max_new_tokens, do_sample=False,
                                    pad_token_id=pad)
        return inner.decode(out[0, ids.shape[1]:], skip_special_tokens=True)

    return ask
