"""``--executor cap``: Code as Policies. The model writes a Python program against the
tabletop robot API (see :mod:`activeintent.act.robot_api`); the program runs in the sandbox and
the robot calls it made become the plan for y.

Building the executor checks that programs can run isolated (bubblewrap namespaces) and raises
:class:`~activeintent.act.isolation.SandboxUnavailable` (a ``ValueError``, with the reason)
when they cannot and the user did not pass ``--unsafe-no-isolation``.
"""

from __future__ import annotations

import re

from activeintent.act.base import Executor, render_prompt
from activeintent.act.failures import ExecutionFailure, PlanResult
from activeintent.act.isolation import require_isolation
from activeintent.act.sandbox import Sandbox, default_sandbox
from activeintent.llm.base import ChatModel, Message, ModelError
from activeintent.world.state import WorldState

_FENCE_RE = re.compile(r"```(?:python|py)?[ \t]*\n(?P<code>.*?)(?:```|$)", re.DOTALL)


def extract_program(text: str) -> str:
    """The code in a model's answer: the first fenced block if there is one, else all of it."""
    if m := _FENCE_RE.search(text):
        return m["code"].strip("\n")
    return text.strip("\n")


class CapExecutor(Executor):
    """y → program (one model call) → sandboxed run → recorded skills."""

    name = "cap"

    def __init__(self, model: ChatModel | None = None, *, sandbox: Sandbox | None = None, max_tokens: int = 512,
                 parser_first: bool = False) -> None:
        super().__init__(model, parser_first=parser_first)
        if sandbox is None and model is not None:
            require_isolation()  # refuse now, with the reason, rather than at every program
        self.sandbox = sandbox
        self.max_tokens = max_tokens

    def messages(self, instruction: str, state: WorldState) -> tuple[list[Message], str]:
        one_line = " ".join(instruction.split()).rstrip(".")  # y goes into one comment line
        prompt, version = render_prompt("executor_cap", objects=repr(list(state.names)), instruction=one_line)
        return [Message(role="user", content=prompt)], version

    def _from_model(self, instruction: str, state: WorldState) -> PlanResult:
        assert self.model is not None
        messages, version = self.messages(instruction, state)
        try:
            answer = self.model.chat(messages, temperature=0.0, max_tokens=self.max_tokens, prompt_version=version)
        except ModelError as e:
            return PlanResult(
                source=self.name,
                failure=ExecutionFailure(stage="program", message=f"the model wrote no program: {e}"),
            )
        return self.run_program(extract_program(answer), state)

    def run_program(self, program: str, state: WorldState) -> PlanResult:
        """Run a (model-written) program in the sandbox; its robot calls become the plan."""
        sandbox = self.sandbox or default_sandbox()
        result = sandbox.run(program, state)
        details = {"kind": result.error_kind, "line": result.line, "said": result.said}
        failure = None
        if result.error is not None:
            # The steps made before the error stay in the plan, as the real robot would have done them.
            where = f" (line {result.line})" if result.line else ""
            failure = ExecutionFailure(stage="program", message=f"{result.error}{where}", details=details)
        elif not result.skills:
            failure = ExecutionFailure(
                stage="program", message="the program made no robot calls (nothing would move)", details=details
            )
        return PlanResult(plan=result.skills, failure=failure, source=self.name, program=program, said=result.said)
