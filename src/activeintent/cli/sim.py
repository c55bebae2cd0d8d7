"""CLI commands of the simulator: `sim-demo` and `sim-bench` (imports stay inside)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from activeintent.world import PutAt, PutIn, PutNextTo, PutOn

DEMO_SCENE = ("red block", "green block", "yellow block", "blue bowl", "purple bowl")


def _demo_plan() -> list:
    return [
        PutIn(block="red block", bowl="blue bowl"),
        PutOn(block="green block", target="yellow block"),
        PutNextTo(block="green block", target="purple bowl", side="nearest"),
        PutAt(block="yellow block", position="bottom right corner"),
    ]


def register(app: typer.Typer) -> None:
    @app.command("sim-demo")
    def sim_demo(
        out: Annotated[Path, typer.Option(help="folder for the GIF, WebM and trajectory")] = Path("out/sim-demo"),
        seed: Annotated[int, typer.Option(help="seed of the scene layout")] = 0,
        fps: Annotated[int, typer.Option(min=1, help="frames per second of the videos")] = 10,
        size: Annotated[int, typer.Option(min=16, max=2048, help="video width and height in pixels")] = 240,
    ) -> None:
        """Build a seeded scene, run a 4-step plan in PyBullet, write a GIF and a WebM."""
        from rich.console import Console
        from rich.progress import Progress

        # lazy: PyBullet loads only for sim-demo and sim-bench
        from activeintent.sim.env import PyBulletEnv
        from activeintent.sim.video import export_video
        from activeintent.world import describe_plan, describe_state

        console = Console()
        plan = _demo_plan()
        with PyBulletEnv() as env:
            state = env.reset(list(DEMO_SCENE), seed)
            console.print(f"[bold]Scene[/] (seed {seed}): {', '.join(DEMO_SCENE)}")
            console.print(f"[bold]Before:[/] {describe_state(state)}")
            console.print(f"[bold]Plan:[/] {describe_plan(plan)}")
            traj = env.execute(plan)
        for step in traj.steps:
            mark = "[green]ok[/]" if step.ok else f"[red]failed[/]: {step.reason}"
            console.print(f"  step {step.index + 1}: {mark}")
        assert traj.final_state is not None
        console.print(f"[bold]After:[/] {describe_state(traj.final_state)}")
        out.mkdir(parents=True, exist_ok=True)
        traj.save(out / "trajectory.npz")
        with Progress(console=console, transient=True) as progress:
            for suffix in (".gif", ".webm"):
                task = progress.add_task(f"rendering {suffix}", total=None)
                path = export_video(
                    traj, out / f"demo{suffix}", fps=fps, size=(size, size),
                    progress=lambda done, total, task=task: progress.update(task, completed=done, total=total),
                )
                console.print(f"wrote {path}")
        console.print(f"wrote {out / 'trajectory.npz'} ({traj.duration:.1f} s simulated)")

    @app.command("sim-bench")
    def sim_bench(
        json_out: Annotated[bool, typer.Option("--json", help="print one JSON object only")] = False,
        repeats: Annotated[int, typer.Option(min=1, help="repetitions of each measurement")] = 3,
    ) -> None:
        """Measure the simulator: physics steps/s, ms per frame, s per pick-and-place and per plan with video."""
        import json
        import tempfile
        import time

        import pybullet as p

        # lazy: PyBullet loads only for sim-demo and sim-bench
        from activeintent.sim.env import PyBulletEnv
        from activeintent.sim.render import render_frame
        from activeintent.sim.video import export_video
        results: dict[str, float | int | str] = {}
        with PyBulletEnv() as env:
            env.reset(list(DEMO_SCENE), 0)
            n = 2000
            start = time.perf_counter()
            for _ in range(n):
                p.stepSimulation(physicsClientId=env.client)
            results["steps_per_s"] = round(n / (time.perf_counter() - start), 1)

            pick_place, pick_place_cpu = [], []
            for r in range(repeats):
                env.reset(list(DEMO_SCENE), r)
                start, cpu = time.perf_counter(), time.process_time()
                traj = env.execute(_demo_plan()[:1])
                pick_place.append(time.perf_counter() - start)
                pick_place_cpu.append(time.process_time() - cpu)
                if not traj.steps[0].ok:
                    raise RuntimeError(f"benchmark pick-and-place failed: {traj.steps[0].reason}")
            results["s_per_pick_place"] = round(min(pick_place), 3)
            # CPU time of this process: the same figure on a machine busy with other work.
            results["cpu_s_per_pick_place"] = round(min(pick_place_cpu), 3)
            results["sim_s_per_pick_place"] = round(traj.duration, 2)

            render_frame(traj, 0.0)  # build the cached renderer once
            times = [traj.duration * i / 30 for i in range(30)]
            start = time.perf_counter()
            for t in times:
                render_frame(traj, t, size=(240, 240))
            results["ms_per_frame"] = round(1000 * (time.perf_counter() - start) / len(times), 2)

            plan_video = []
            with tempfile.TemporaryDirectory() as tmp:
                for _ in range(repeats):
                    start = time.perf_counter()
                    env.reset(list(DEMO_SCENE), 0)
                    traj = env.execute(_demo_plan())
                    export_video(traj, Path(tmp) / "plan.webm", fps=10, size=(240, 240))
                    plan_video.append(time.perf_counter() - start)
            results["s_per_plan_with_video"] = round(min(plan_video), 3)
            results["plan_video_s"] = round(traj.duration, 2)
            results["plan_steps_ok"] = sum(s.ok for s in traj.steps)
        results["targets"] = "s_per_pick_place < 0.5, s_per_plan_with_video < 10"
        if json_out:
            typer.echo(json.dumps(results))
            return
        from rich.console import Console
        from rich.table import Table

        table = Table(title="sim-bench")
        table.add_column("measure")
        table.add_column("value", justify="right")
        for key, value in results.items():
            table.add_row(key, str(value))
        Console().print(table)
