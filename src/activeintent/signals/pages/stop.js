// The stop signal's page: one video τ. Behind a ready gate until the participant presses Ready; then it
// plays once and Stop records the media time of the frame on screen (the server maps it to
// the trajectory tick). When it ends, Stop is off: a late press is logged as "after end" and
// never sent as a stop. Looks good once it has ended; Replay after the end, and a stop during a
// replay is sent flagged as such (viewing: "replay"). New scene at any time.
// After a stop the video stays paused on the frame the participant stopped at, with a marker,
// until the next round is ready.
"use strict";

(() => {
  const video = document.getElementById("video");
  const card = document.getElementById("video-card");
  const stage = document.getElementById("stage");
  const question = document.getElementById("question");
  const badge = document.getElementById("stop-badge");
  const timeline = document.getElementById("timeline");
  const stopBtn = document.getElementById("stop");
  const goodBtn = document.getElementById("good");
  const newBtn = document.getElementById("new-scene");
  const playBtn = document.getElementById("play");
  const replayBtn = document.getElementById("replay");
  const status = document.getElementById("status");
  let round = null; // the round on screen and not yet answered
  let shownRound = null;
  let stoppedAt = null; // media time of the accepted stop, while its frame stays on screen
  // gate → first → ended (→ replay → ended …); the stop button works in first and replay only
  let phase = "gate";
  let endedAt = null; // client time the first viewing ended
  // the video's length from the server: a video still being drawn plays before the browser knows it
  let length = null;

  Study.watchVideo(video, "robot", () => shownRound);
  Study.setupLegend(document.getElementById("legend-toggle"), document.getElementById("legend"), () => shownRound);

  function setPhase(p) {
    phase = p;
    question.dataset.phase = p;
    setEnabled(round !== null);
  }

  function fraction(t) {
    const d = Number.isFinite(video.duration) ? video.duration : length;
    return Number.isFinite(d) && d > 0 ? Math.min(1, Math.max(0, t / d)) : 0;
  }
  video.addEventListener("timeupdate", () => {
    if (stoppedAt === null) timeline.querySelector(".played").style.width = `${100 * fraction(video.currentTime)}%`;
  });
  video.addEventListener("ended", () => {
    if (round === null || (phase !== "first" && phase !== "replay")) return;
    const first = phase === "first";
    if (first) endedAt = Study.now();
    setPhase("ended");
    replayBtn.classList.remove("hidden");
    // the server refuses first-viewing stops from now on (its own check of late presses)
    if (first) Study.reportVideo(round, "ended", video.currentTime).catch(() => {});
  });
  playBtn.addEventListener("click", () => {
    Study.log("play_clicked", {}, shownRound);
    playBtn.classList.add("hidden");
    video.play().catch(() => {});
  });
  replayBtn.addEventListener("click", async () => {
    if (round === null || phase !== "ended") return;
    replayBtn.disabled = true;
    try {
      await Study.reportVideo(round, "replay", 0); // before any stop of the replay can be sent
    } catch (err) {
      Study.log("replay_refused", { error: err.message, code: err.code ?? null }, shownRound);
      status.textContent = Study.friendly(err, "The video cannot be replayed now. Please choose an answer.");
      replayBtn.disabled = false;
      return;
    }
    replayBtn.disabled = false;
    replayBtn.classList.add("hidden");
    Study.log("replay", { video: "robot" }, shownRound);
    status.textContent = "Replay: you may still stop the robot.";
    setPhase("replay");
    Study.restart(video);
  });

  function markStop(t) {
    stoppedAt = t;
    card.classList.add("stopped");
    badge.textContent = `Stopped here · ${t.toFixed(2)} s`;
    badge.classList.remove("hidden");
    const marker = timeline.querySelector(".marker");
    marker.style.left = `${100 * fraction(t)}%`;
    marker.classList.remove("hidden");
    timeline.querySelector(".played").style.width = `${100 * fraction(t)}%`;
  }

  function clearStop() {
    stoppedAt = null;
    card.classList.remove("stopped");
    badge.classList.add("hidden");
    timeline.querySelector(".marker").classList.add("hidden");
    timeline.querySelector(".played").style.width = "0%";
  }

  function setEnabled(on) {
    stopBtn.disabled = !(on && (phase === "first" || phase === "replay"));
    newBtn.disabled = !(on && phase !== "gate"); // not before the participant has seen the table
    goodBtn.disabled = !(on && phase === "ended");
  }

  // A stop once the video has ended is no stop: say so, keep it in the log, send nothing.
  function lateStop(via) {
    Study.log("stop_after_end", { via, time: video.currentTime, duration: video.duration,
      since_end_s: endedAt === null ? null : Study.now() - endedAt }, round);
    status.textContent = "The video has ended, so Stop no longer counts: choose Looks good, or Replay to watch it again.";
  }

  async function send(action, via) {
    if (round === null) return;
    if (action === "stop" && phase === "ended") return lateStop(via);
    if (action === "stop" && phase !== "first" && phase !== "replay") return;
    const answering = round;
    round = null;
    const body = { kind: "stop", round: answering, action, client_ts: Study.now() };
    if (action === "stop") {
      video.pause(); // freeze the frame the participant reacted to
      body.time = video.currentTime;
      body.viewing = phase === "replay" ? "replay" : "first";
    }
    setEnabled(false);
    Study.log(action, { via, time: video.currentTime, duration: video.duration, viewing: body.viewing ?? null }, answering);
    status.textContent = action === "stop" ? `Stopped at ${video.currentTime.toFixed(2)} s. Sending…` : "Sending…";
    try {
      await Study.api("POST", `/api/sessions/${Study.sessionId}/answer`, body);
      Study.log("answer_accepted", { action, time: body.time ?? null }, answering);
      replayBtn.classList.add("hidden");
      if (action === "stop") {
        markStop(body.time);
        status.textContent = `You stopped the robot at ${body.time.toFixed(2)} s.`;
        Study.setWaiting(true, "Thank you. The robot is thinking about what you showed it…", true);
      } else {
        status.textContent = "";
        Study.setWaiting(true, "Thank you. The robot is thinking about what you showed it…");
      }
    } catch (err) {
      Study.log("answer_rejected", { action, error: err.message, code: err.code ?? null }, answering);
      status.textContent = Study.friendly(err, "Your answer could not be saved. Please try again.");
      round = answering;
      setEnabled(true);
    }
    Study.flush();
  }

  stopBtn.addEventListener("click", () => send("stop", "click"));
  goodBtn.addEventListener("click", () => send("no_stop", "click"));
  newBtn.addEventListener("click", () => send("new_scene", "click"));
  document.addEventListener("keydown", (e) => {
    if (Study.isTyping(e) || e.repeat || e.ctrlKey || e.metaKey || e.altKey) return;
    const k = e.key === " " ? "space" : e.key.toLowerCase();
    const action = { space: "stop", g: "no_stop", n: "new_scene" }[k];
    if (!action) return;
    if (round === null && e.target && e.target.tagName === "BUTTON") return; // e.g. Continue, Show colour names
    e.preventDefault(); // space must not scroll or press a focused button
    Study.log("key", { key: k, phase }, round);
    if (action === "no_stop" && goodBtn.disabled) return;
    send(action, "key");
  });

  function show(q) {
    const v = q.videos[0];
    length = v.duration;
    clearStop();
    Study.fillLegend(document.getElementById("legend-list"), q.legend);
    Study.describeVideo(video, document.getElementById("caption"), "The robot tidying this table", q.legend, v.duration);
    playBtn.classList.add("hidden");
    replayBtn.classList.add("hidden");
    video.removeAttribute("src");
    round = q.round;
    endedAt = null;
    stage.classList.add("gated");
    setPhase("gate");
    Study.setWaiting(false);
    question.dataset.round = String(q.round);
    status.textContent = "";
    Study.log("round_shown", { video: v.url, duration: v.duration, fps: v.fps }, q.round);
    const gate = document.getElementById("gate");
    const loading = Study.loadForGate(gate, [{ video, v }], q.round);
    Study.readyGate(gate, q.round, () => {
      stage.classList.remove("gated");
      setPhase("first");
      video.play().catch((err) => {
        if (err.name === "NotAllowedError") playBtn.classList.remove("hidden"); // autoplay blocked
      });
    }, loading);
  }

  Study.log("page_load", { page: "stop" });
  Study.poll((s) => {
    if (s.page !== location.pathname) return Study.goTo(s.page);
    if (Study.routeFinished(s)) return;
    Study.setProgress(s);
    Study.setEstimate(s);
    Study.orderButtons(document.getElementById("answers"), "data-action", s.button_order);
    if (s.status === "waiting-for-answer" && s.question && s.question.round !== shownRound) {
      shownRound = s.question.round;
      status.textContent = ""; // the last round's words do not outlive its frame
      Study.betweenRounds(s, () => show(s.question));
    } else if (s.status === "waiting-for-learner") {
      round = null;
      setEnabled(false);
      Study.setWaiting(true, s.phase === "final"
        ? "Thank you! The robot is now trying what it learned on a new table…"
        : "The robot is thinking about what you showed it…", stoppedAt !== null);
    }
  });
})();
