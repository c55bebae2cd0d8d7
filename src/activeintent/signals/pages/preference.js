// The preference signal's page: two videos τ^a, τ^b side by side; the answer is A, B, Can't choose or New scene.
"use strict";

(() => {
  const videos = { A: document.getElementById("video-a"), B: document.getElementById("video-b") };
  const choiceButtons = [...document.querySelectorAll("button[data-choice]")];
  const status = document.getElementById("status");
  const keys = { a: "A", b: "B", c: "cant_choose", n: "new_scene" };
  let round = null; // the round on screen and not yet answered
  let shownRound = null;
  const videosBox = document.getElementById("videos");

  Study.watchVideo(videos.A, "A", () => shownRound);
  Study.watchVideo(videos.B, "B", () => shownRound);
  Study.setupLegend(document.getElementById("legend-toggle"), document.getElementById("legend"), () => shownRound);

  function replay(which) {
    if (videosBox.classList.contains("gated")) return; // nothing plays before Ready
    Study.log("replay", { video: which }, shownRound);
    for (const v of which === "both" ? [videos.A, videos.B] : [videos[which]]) Study.restart(v);
  }
  document.getElementById("replay-a").addEventListener("click", () => replay("A"));
  document.getElementById("replay-b").addEventListener("click", () => replay("B"));
  document.getElementById("replay-both").addEventListener("click", () => replay("both"));

  function setEnabled(on) {
    choiceButtons.forEach((b) => (b.disabled = !on));
  }

  async function answer(choice, via) {
    if (round === null) return;
    const answering = round;
    round = null;
    setEnabled(false);
    Study.log("choice", { choice, via }, answering);
    status.textContent = "Sending…";
    try {
      await Study.api("POST", `/api/sessions/${Study.sessionId}/answer`, {
        kind: "preference", round: answering, choice, client_ts: Study.now(),
      });
      Study.log("answer_accepted", { choice }, answering);
      status.textContent = "";
      Object.values(videos).forEach((v) => v.pause());
      Study.setWaiting(true, "Thank you. The robot is thinking about what to show you next…");
    } catch (err) {
      Study.log("answer_rejected", { choice, error: err.message }, answering);
      status.textContent = Study.friendly(err, "Your answer could not be saved. Please try again.");
      round = answering;
      setEnabled(true);
    }
    Study.flush();
  }

  choiceButtons.forEach((b) => b.addEventListener("click", () => answer(b.dataset.choice, "click")));
  document.addEventListener("keydown", (e) => {
    if (Study.isTyping(e) || e.repeat || e.ctrlKey || e.metaKey || e.altKey) return;
    const choice = keys[e.key.toLowerCase()];
    if (!choice) return;
    Study.log("key", { key: e.key }, round);
    e.preventDefault();
    answer(choice, "key");
  });

  // The videos load behind the ready gate and play, with the answers enabled, once the
  // participant says they are ready.
  function show(q) {
    Study.fillLegend(document.getElementById("legend-list"), q.legend);
    for (const v of q.videos) {
      const el = videos[v.label];
      const which = v.label === "A" ? "first" : "second";
      Study.describeVideo(el, document.getElementById(`caption-${v.label.toLowerCase()}`),
        `Video ${v.label}: the robot's ${which} way of tidying this table`, q.legend, v.duration);
      el.removeAttribute("src");
    }
    round = null;
    setEnabled(false);
    videosBox.classList.add("gated");
    Study.setWaiting(false);
    const question = document.getElementById("question");
    question.dataset.round = String(q.round);
    question.dataset.phase = "gate";
    Study.log("round_shown", { videos: q.videos.map((v) => v.url) }, q.round);
    const gate = document.getElementById("gate");
    const loading = Study.loadForGate(gate, q.videos.map((v) => ({ video: videos[v.label], v })), q.round);
    Study.readyGate(gate, q.round, () => {
      videosBox.classList.remove("gated");
      question.dataset.phase = "playing";
      for (const el of Object.values(videos)) el.play().catch(() => {});
      round = q.round;
      setEnabled(true);
    }, loading);
  }

  Study.log("page_load", { page: "preference" });
  Study.poll((s) => {
    if (s.page !== location.pathname) return Study.goTo(s.page);
    if (Study.routeFinished(s)) return;
    Study.setProgress(s);
    Study.setEstimate(s);
    Study.orderButtons(document.getElementById("answers"), "data-choice", s.button_order);
    if (s.status === "waiting-for-answer" && s.question && s.question.round !== shownRound) {
      shownRound = s.question.round;
      Study.betweenRounds(s, () => show(s.question));
    } else if (s.status === "waiting-for-learner") {
      round = null;
      setEnabled(false);
      Study.setWaiting(true, s.phase === "final"
        ? "Thank you! The robot is now trying what it learned on a new table…"
        : "The robot is thinking about what to show you next…");
    }
  });
})();
