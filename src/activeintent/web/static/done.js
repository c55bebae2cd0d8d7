// Done page: the robot's final attempt, then the end-of-session questionnaire. The learner's
// final guess (in studies that show guesses) appears only after the questionnaire is sent, so
// it cannot colour the participant's description of their own rule.
"use strict";

(() => {
  const video = document.getElementById("final");
  const form = document.getElementById("questionnaire");
  const qStatus = document.getElementById("q-status");
  const submit = document.getElementById("q-submit");
  let state = null;

  Study.watchVideo(video, "final", () => null);
  Study.setupLegend(document.getElementById("legend-toggle"), document.getElementById("legend"), () => null);
  const replayBtn = document.getElementById("replay");

  // The questions open only once the final attempt has played to its end (a reload keeps that);
  // what is sent with the answers: whether it was watched to the end or also replayed, and the
  // seconds it played on screen.
  const WATCH_KEY = `activeintent.finalWatched.${Study.sessionId}`;
  const watch = (() => {
    try { return JSON.parse(sessionStorage.getItem(WATCH_KEY)) || { ended: false, replays: 0, seconds: 0 }; }
    catch (_) { return { ended: false, replays: 0, seconds: 0 }; }
  })();
  const keepWatch = () => { try { sessionStorage.setItem(WATCH_KEY, JSON.stringify(watch)); } catch (_) { /* private mode */ } };
  let lastTime = null;
  video.addEventListener("timeupdate", () => {
    const t = video.currentTime;
    if (!video.paused && lastTime !== null && t > lastTime) watch.seconds += Math.min(t - lastTime, 1);
    lastTime = t;
  });
  video.addEventListener("seeking", () => { lastTime = null; });
  // the server keeps its own record of the viewing: it opens the questions only after "ended"
  const report = (event) => Study.api("POST", `/api/sessions/${Study.sessionId}/final-video`,
    { event, media_time: video.currentTime, client_ts: Study.now() });
  let started = false;
  video.addEventListener("play", () => {
    if (started) return;
    started = true;
    report("ready").catch(() => {});
  });
  video.addEventListener("ended", async () => {
    lastTime = null;
    if (!watch.ended) Study.log("final_watched", { seconds: watch.seconds });
    watch.ended = true;
    keepWatch();
    replayBtn.classList.remove("hidden");
    try { await report("ended"); } catch (_) { /* the questionnaire's answer says so if it did not arrive */ }
    setLocked(false);
  });
  replayBtn.addEventListener("click", () => {
    if (document.getElementById("stage").classList.contains("gated")) return;
    watch.replays += 1;
    keepWatch();
    report("replay").catch(() => {});
    Study.log("replay", { video: "final" });
    lastTime = null;
    video.currentTime = 0;
    video.play().catch(() => {});
  });
  function setLocked(locked) {
    form.dataset.locked = String(locked);
    document.getElementById("q-locked").classList.toggle("hidden", !locked);
    for (const el of form.querySelectorAll("input, textarea, button")) el.disabled = locked;
  }

  let redirecting = false;
  function finish(s) {
    form.classList.add("hidden");
    document.getElementById("finished").classList.remove("hidden");
    const box = document.getElementById("estimate");
    const guess = s && s.estimate;
    box.classList.toggle("hidden", !guess);
    Study.fillGuess(box, guess || null);
    if (s && s.completion) showCompletion(s.completion);
    else if (s && !s.questionnaire.submitted) refresh(); // the code comes with the state once the answers are in
  }

  async function refresh() {
    try {
      const s = await Study.api("GET", `/api/sessions/${Study.sessionId}`);
      if (s.completion) showCompletion(s.completion);
    } catch (_) { /* the poll reports lost contact */ }
  }

  // The study file's completion code and redirect (e.g. back to Prolific).
  function showCompletion(c) {
    const box = document.getElementById("completion");
    if (!c.code && !c.redirect_url) return;
    box.classList.remove("hidden");
    document.getElementById("completion-code").textContent = c.code || "";
    box.querySelector("p").classList.toggle("hidden", !c.code);
    if (!c.redirect_url) return;
    const link = document.getElementById("redirect-link");
    link.href = c.redirect_url;
    link.classList.remove("hidden");
    if (typeof c.redirect_after_s === "number" && !redirecting) {
      redirecting = true;
      document.getElementById("redirect-note").textContent = `(you are taken there in ${c.redirect_after_s} s)`;
      Study.log("redirect_scheduled", { after_s: c.redirect_after_s });
      Study.flush();
      setTimeout(() => { location.href = c.redirect_url; }, 1000 * c.redirect_after_s);
    }
  }

  form.addEventListener("submit", async (e) => {
    e.preventDefault();
    if (!state) return;
    const asks = state.questionnaire.asks_final_attempt;
    const picked = form.querySelector('input[name="final_attempt"]:checked');
    const rule = document.getElementById("q-rule").value.trim();
    const comments = document.getElementById("q-comments").value.trim();
    const missing = [];
    if (asks && !picked) missing.push("whether the final attempt did what you wanted");
    if (!rule) missing.push("your rule");
    if (missing.length) {
      qStatus.textContent = `Please answer ${missing.join(" and ")}.`;
      qStatus.classList.add("error");
      (asks && !picked ? form.querySelector('input[name="final_attempt"]') : document.getElementById("q-rule")).focus();
      return;
    }
    const body = { rule, client_ts: Study.now() };
    if (asks) body.final_attempt = picked.value;
    if (state.final_video && watch.ended) {
      body.final_video_watched = watch.replays > 0 ? "replayed" : "ended";
      body.final_video_seconds = Math.round(watch.seconds * 100) / 100;
    }
    if (comments) body.comments = comments;
    submit.disabled = true;
    qStatus.classList.remove("error");
    qStatus.textContent = "Sending…";
    try {
      await Study.api("POST", `/api/sessions/${Study.sessionId}/questionnaire`, body);
      Study.log("questionnaire_sent", { final_attempt: body.final_attempt ?? null });
      finish(state);
    } catch (err) {
      if (err.code === "already_submitted") { finish(state); return; }
      Study.log("questionnaire_rejected", { error: err.message });
      qStatus.textContent = Study.friendly(err, "Your answers could not be saved. Please check them and try again.");
      qStatus.classList.add("error");
      submit.disabled = false;
    }
    Study.flush();
  });

  Study.log("page_load", { page: "done" });
  Study.poll((s) => {
    Study.setProgress(s);
    if (s.status === "waiting-for-answer") {
      return Study.goTo(s.page);
    }
    if (s.status === "waiting-for-learner") return;
    const first = state === null;
    state = s;
    Study.setWaiting(false);
    if (s.questionnaire.submitted) {
      finish(s);
      if (!first) return;
    }
    if (!first) return;
    document.getElementById("q-final").classList.toggle("hidden", !s.questionnaire.asks_final_attempt);
    if (s.status !== "finished") {
      document.getElementById("thanks-text").textContent =
        "The session ended early, so there is no final attempt to show. Please still tell us about your rule.";
      document.getElementById("final-card").classList.add("hidden");
      Study.log("ended_early", { status: s.status });
    } else if (s.final_video) {
      Study.fillLegend(document.getElementById("legend-list"), s.final_legend);
      Study.describeVideo(video, document.getElementById("final-caption"),
        "The robot's final attempt on a new table", s.final_legend, s.final_video.duration);
      document.getElementById("stage").classList.add("gated");
      replayBtn.classList.toggle("hidden", !watch.ended);
      setLocked(!watch.ended);
      const gate = document.getElementById("gate");
      const loading = Study.loadForGate(gate, [{ video, v: s.final_video }], null);
      Study.readyGate(gate, null, () => {
        document.getElementById("stage").classList.remove("gated");
        video.play().catch(() => {});
      }, loading);
    } else {
      document.getElementById("final-card").classList.add("hidden");
    }
    if (s.design === "assigned-rule") {
      document.getElementById("q-rule-label").textContent =
        "In your own words, what rule were you teaching the robot?";
    }
  });
})();
