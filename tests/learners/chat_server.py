"""A scripted OpenAI-compatible chat server on loopback for end-to-end learner tests.

It answers the faithful learners' structured requests (by the response_format's schema name)
and Code-as-Policies requests (free text) with canned content. At temperature > 0 it *samples*:
the answer is drawn with a generator seeded by the request's ``seed`` and messages, so two
requests that differ only in their seed get different draws, like a real sampling server.
Every request body is kept in ``requests``.
"""

from __future__ import annotations

import json
import random
import threading
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from typing import Any

GOALS = [
    "sort every block into the bowl that shares its colour",
    "give each block the bowl of its own colour",
    "match the blocks with the bowls by colour",
]
LANG_GOAL = {"clauses": [{"quantifier": "every", "blocks": "class:warm", "predicate": "in-bowl:other"},
                         {"quantifier": "every", "blocks": "class:cool", "predicate": "in-bowl:other"},
                         {"quantifier": "none", "blocks": "all:", "predicate": "on-block:any"}],
             "others_stay": False}
PREFERENCES = ["blocks belong with bowls of their colour", "colour decides the bowl", "like goes with like"]
SCENES = [
    ["red block", "blue block", "red bowl", "blue bowl"],
    ["green block", "yellow block", "purple block", "green bowl", "yellow bowl"],
    ["pink block", "cyan block", "pink bowl"],
]
PROGRAM = (
    "bowls = [n for n in get_obj_names() if n.endswith('bowl')]\n"
    "for b in [n for n in get_obj_names() if n.endswith('block')]:\n"
    "    w = b.replace('block', 'bowl')\n"
    "    put_first_on_second(b, w if w in bowls else bowls[0])\n"
)


def _completion(content: str, model: str) -> dict[str, Any]:
    return {"id": "chatcmpl-scripted", "object": "chat.completion", "created": 0, "model": model,
            "choices": [{"index": 0, "message": {"role": "assistant", "content": content}, "finish_reason": "stop"}],
            "usage": {"prompt_tokens": 10, "completion_tokens": 10, "total_tokens": 20}}


def schema_name(body: dict[str, Any]) -> str | None:
    fmt = body.get("response_format") or {}
    return (fmt.get("json_schema") or {}).get("name")


class ChatServer:
    def __init__(self, garbage_for: set[int] | None = None) -> None:
        self.requests: list[dict[str, Any]] = []
        self.garbage_for = garbage_for or set()  # indexes of requests answered with non-JSON
        server = self

        class Handler(BaseHTTPRequestHandler):
            protocol_version = "HTTP/1.1"

            def log_message(self, *args: Any) -> None:
                pass

            def do_POST(self) -> None:
                body = json.loads(self.rfile.read(int(self.headers.get("Content-Length", 0))) or b"{}")
                server.requests.append(body)
                content = server.answer(body, len(server.requests) - 1)
                payload = json.dumps(_completion(content, body.get("model", ""))).encode()
                self.send_response(200)
                self.send_header("Content-Type", "application/json")
                self.send_header("Content-Length", str(len(payload)))
                self.end_headers()
                self.wfile.write(payload)

        self.httpd = ThreadingHTTPServer(("127.0.0.1", 0), Handler)
        self.httpd.daemon_threads = True
        self.thread = threading.Thread(target=self.httpd.serve_forever, args=(0.02,), daemon=True)

    def answer(self, body: dict[str, Any], index: int) -> str:
        if index in self.garbage_for:
            return "I would rather not answer in JSON today."
        temperature = float(body.get("temperature") or 0.0)
        draw = json.dumps([body.get("seed"), body.get("messages")], sort_keys=True) if temperature > 0 else "fixed"
        rng = random.Random(draw)
        name = schema_name(body)
        if name is None:  # Code as Policies: a program for the instruction in the last comment
            return f"```python\n{PROGRAM}```"
        if name == "FaithfulScene":
            objects = rng.choice(SCENES)
            return json.dumps({"reasoning": f"draw {rng.random():.6f}", "blocks": [o for o in objects if o.endswith("block")],
                               "bowls": [o for o in objects if o.endswith("bowl")]})
        if name in ("FaithfulAnswer", "FaithfulPairAnswer"):
            out = {"reasoning": f"draw {rng.random():.6f}", "preference": rng.choice(PREFERENCES)}
            if name == "FaithfulAnswer":
                out["goal"] = rng.choice(GOALS)
            else:
                out["goal_a"], out["goal_b"] = rng.sample(GOALS, 2)
                out["done"] = True  # says it is sure: the benchmark runs K rounds anyway
            return json.dumps(out)
        if name == "GoalProposals":  # the lang learner: goals in the language (one fits, one does not)
            return json.dumps({"goals": [LANG_GOAL, {"clauses": [
                {"quantifier": "form", "blocks": "all:", "predicate": "in-bowl:same"}], "others_stay": False}]})
        if name == "FaithfulRetrieval":
            return json.dumps({"reasoning": "looked", "retrieved": "the person did not like that bowl"})
        raise AssertionError(f"unexpected schema {name}")

    @property
    def base_url(self) -> str:
        return f"http://127.0.0.1:{self.httpd.server_address[1]}/v1"

    def __enter__(self) -> ChatServer:
        self.thread.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self.httpd.shutdown()
        self.httpd.server_close()
        self.thread.join(timeout=5)
