// Shared by the study pages: the API, raw-event logging, polling and page switching.
"use strict";

const Study = (() => {
  const params = new URLSearchParams(location.search);
  const sessionId = params.get("session");
  let queue = [];
  const now = () => Date.now() / 1000;
  let flushing = false;

  async function api(method, path, body) {
    const res = await fetch(path, {
      method,
      headers: body === undefined ? {} : { "Content-Type": "application/json" },
      body: body === undefined ? undefined : JSON.stringify(body),
      cache: "no-store",
    });
    let data = null;
    try { data = await res.json(); } catch (_) { data = null; }
    if (!res.ok) {
      // every error body is {"error": {"status", "code", "message"}}
      const info = data && data.error ? data.error : {};
      const err = new Error(typeof info.message === "string" ? info.message : `HTTP ${res.status}`);
      err.status = res.status;
      err.code = info.code;
      throw err;
    }
    return data;
  }

  // Every raw UI event goes to events.jsonl with its client timestamp (seconds since the epoch).
  function log(type, data = {}, round = null) {
    if (!sessionId) return;
    queue.push({ type, client_ts: now(), round, data });
    if (queue.length >= 20) flush();
  }

  async function flush() {
    if (!sessionId || flushing || queue.length === 0) return;
    flushing = true;
    const batch = queue.splice(0, 200);
    try {
      await api("POST", `/api/sessions/${sessionId}/events`, { events: batch });
    } catch (err) {
      if (err.status === undefined) queue = batch.concat(queue); // network hiccup: retry later
    } finally {
      flushing = false;
    }
  }

  function flushNow() {
    // Used when the page goes away: a beacon survives the unload.
    if (!sessionId || queue.length === 0) return;
    const blob = new Blob([JSON.stringify({ events: queue.splice(0, 200) })], { type: "application/json" });
    navigator.sendBeacon(`/api/sessions/${sessionId}/events`, blob);
  }

  setInterval(flush, 1000);
  addEventListener("pagehide", () => {
    flushNow();
    // the page is going away (closed, reloaded or the next page): unless a page of this session
    // asks again within the server's reconnect grace, the session ends and frees its slot
    if (sessionId) navigator.sendBeacon(`/api/sessions/${sessionId}/leave`);
  });
  document.addEventListener("visibilitychange", () => log("visibility", { state: document.visibilityState }));

  function goTo(page) {
    flushNow();
    location.href = `${page}?session=${encodeURIComponent(sessionId)}`;
  }

  // Poll the session state; onState(state) is called on every change of status or round.
  function poll(onState, interval = 400) {
    let last = "";
    async function tick() {
      try {
        const s = await api("GET", `/api/sessions/${sessionId}`);
        const key = `${s.status}|${s.question ? s.question.round : "-"}|${s.phase}|${JSON.stringify(s.estimate)}|${JSON.stringify(s.questionnaire)}`;
        if (key !== last) {
          last = key;
          onState(s);
        }
      } catch (err) {
        log("poll_failed", { status: err.status ?? null, code: err.code ?? null });
        showFatal(err.status === 404 ? friendly(err) : "Lost contact with the study server; trying again…");
        if (err.status === 404) return;
      }
      setTimeout(tick, interval);
    }
    tick();
  }

  function setProgress(s) {
    const el = document.getElementById("progress");
    if (!el) return;
    const done = s.status === "finished";
    el.querySelector(".label").textContent = done ? `Done (${s.rounds} of ${s.rounds})` : `Round ${s.progress} of ${s.rounds}`;
    const bar = el.querySelector(".bar");
    const finished = done ? s.rounds : s.progress - 1;
    bar.querySelector("span").style.width = `${(100 * finished) / s.rounds}%`;
    bar.setAttribute("aria-valuemax", String(s.rounds));
    bar.setAttribute("aria-valuenow", String(finished));
    bar.setAttribute("aria-valuetext", done ? "all rounds done" : `round ${s.progress} of ${s.rounds}`);
  }

  // The learner's guess as one sentence plus its confidence, where the learner has one.
  function fillGuess(box, est) {
    box.querySelector(".guess").textContent = est ? est.z : "";
    const conf = box.querySelector(".confidence");
    if (!conf) return;
    if (est && typeof est.confidence === "number") {
      const pct = Math.round(100 * est.confidence);
      const after = `after ${est.answers} answer${est.answers === 1 ? "" : "s"}`;
      conf.textContent = est.kind === "expected_success"
        ? `The robot expects this attempt to do what you want with ${pct}% probability (${after}).`
        : `The robot is ${pct}% sure of this guess (${after}).`;
      conf.title = est.basis || "";
    } else {
      conf.textContent = est ? "This robot does not say how sure it is." : "";
    }
  }

  // The guess above the videos: only in studies that show it "always" (never in round 1:
  // the server gives no guess before the first answer).
  function setEstimate(s) {
    const box = document.getElementById("estimate");
    if (!box) return;
    const show = Boolean(s.estimate) && s.show_estimate === "always";
    box.classList.toggle("hidden", !show);
    fillGuess(box, show ? s.estimate : null);
  }

  // In "after-answer" studies the guess is shown between rounds: once the next round is ready,
  // the page says what the robot now guesses, and the round starts when the participant goes on.
  // The guess is never on screen while the participant decides.
  function betweenRounds(s, proceed) {
    const panel = document.getElementById("feedback");
    if (!panel || s.show_estimate !== "after-answer" || !s.estimate || !s.question) {
      if (panel) panel.classList.add("hidden");
      proceed();
      return;
    }
    const round = s.question.round;
    fillGuess(panel, s.estimate);
    document.getElementById("waiting").classList.remove("shown");
    document.getElementById("question").classList.add("hidden");
    panel.classList.remove("hidden");
    const button = document.getElementById("continue");
    button.textContent = `Continue to round ${s.progress} of ${s.rounds}`;
    button.onclick = () => {
      button.onclick = null;
      panel.classList.add("hidden");
      log("guess_continue", {}, round);
      proceed();
    };
    button.focus();
    log("guess_shown", { z: s.estimate.z, confidence: s.estimate.confidence, answers: s.estimate.answers }, round);
  }

  // keepQuestion: leave what is on screen (e.g. the frame the participant stopped at) visible.
  function setWaiting(shown, text, keepQuestion = false) {
    const w = document.getElementById("waiting");
    const q = document.getElementById("question");
    if (text) w.querySelector("p").textContent = text;
    w.classList.toggle("shown", shown);
    w.classList.toggle("inline", shown && keepQuestion);
    q.classList.toggle("hidden", shown && !keepQuestion);
  }

  // Colour names on request: a legend of the scene's objects next to the video. The choice is
  // remembered for the next rounds and pages.
  const LEGEND_KEY = "activeintent.colourNames";
  function legendWanted() {
    try { return localStorage.getItem(LEGEND_KEY) === "1"; } catch (_) { return false; }
  }
  function setupLegend(toggle, panel, roundOf) {
    const apply = (on) => {
      panel.classList.toggle("hidden", !on);
      toggle.setAttribute("aria-expanded", String(on));
      toggle.textContent = on ? "Hide colour names" : "Show colour names";
    };
    apply(legendWanted());
    toggle.addEventListener("click", () => {
      const on = panel.classList.contains("hidden");
      try { localStorage.setItem(LEGEND_KEY, on ? "1" : "0"); } catch (_) { /* private mode */ }
      apply(on);
      log("colour_names", { shown: on }, roundOf ? roundOf() : null);
    });
  }
  function fillLegend(list, legend) {
    list.replaceChildren();
    for (const item of legend || []) {
      const li = document.createElement("li");
      const swatch = document.createElement("span");
      swatch.className = `swatch ${item.kind}`;
      swatch.setAttribute("aria-hidden", "true");
      if (item.hex) swatch.style.background = item.hex;
      const name = document.createElement("span");
      name.textContent = item.name;
      li.append(swatch, name);
      list.append(li);
    }
  }
  // What a screen reader says about a video: its label and the objects on the table.
  function describeVideo(video, captionEl, label, legend, seconds) {
    video.setAttribute("aria-label", label);
    const names = (legend || []).map((o) => o.name).join(", ");
    const length = typeof seconds === "number" ? ` It lasts ${seconds.toFixed(1)} seconds and has no sound.` : "";
    captionEl.textContent = `${label}.${length} Objects on the table: ${names || "none"}.`;
  }

  // What a participant reads when a request fails: never the server's own sentence (that one
  // goes to the log), but what happened and what to do, in the participant's terms.
  const MESSAGES = {
    too_many_sessions: "This computer already has a study session open (perhaps in another tab or window). " +
      "Please finish or close it; if you closed it, wait a minute and try again.",
    session_rate_limited: "Too many sessions were started from this computer in the last hour. " +
      "Please try again later, or contact the researchers.",
    server_full: "The study is full at the moment. Please try again in a few minutes.",
    server_busy: "The study server is busy at the moment. Please try again in a few minutes.",
    pid_required: "This link has no participant ID. Please open the link you were given.",
    consent_required: "The study starts only once you agree to take part.",
    not_session_owner: "This session was started in another browser or tab, or your cookies were cleared. " +
      "Please open the study link again to start afresh.",
    unknown_session: "This session does not exist any more (the server may have been restarted). " +
      "Please open the study link again.",
    final_video_not_watched: "Please watch the robot's final attempt to its end first; the questions open after it.",
    after_video_end: "The video had already ended, so that Stop did not count. Choose another answer, or replay the video.",
  };
  function friendly(err, fallback = "Something went wrong. Please try again; if it keeps happening, contact the researchers.") {
    if (err && err.code && MESSAGES[err.code]) return MESSAGES[err.code];
    if (err && err.status === undefined) return "The study server cannot be reached. Please check your connection and try again.";
    return fallback;
  }

  function showFatal(msg) {
    const el = document.getElementById("status");
    if (el) { el.textContent = msg; el.classList.add("error"); }
  }

  // Log what the participant does with a video (play, pause, seeks, ends).
  function watchVideo(video, label, roundOf) {
    // the page takes the video's own size (CSS variables), so nothing is drawn smaller than rendered
    video.addEventListener("loadedmetadata", () => {
      if (!video.videoWidth) return;
      document.documentElement.style.setProperty("--video-width", `${video.videoWidth}px`);
      document.documentElement.style.setProperty("--video-aspect", `${video.videoWidth} / ${video.videoHeight}`);
      document.documentElement.style.setProperty("--video-ratio", String(video.videoWidth / video.videoHeight));
    });
    // "waiting": playback paused for frames not yet drawn (videos are shown while they are drawn)
    for (const type of ["loadedmetadata", "play", "playing", "waiting", "pause", "seeked", "ended", "error"]) {
      video.addEventListener(type, () =>
        log(`video_${type}`, { video: label, time: video.currentTime, duration: video.duration }, roundOf()));
    }
    // A stall: from "waiting" until frames flow again ("playing"), or until the round's answer
    // ends it (video_stall_open); one video_stall event each, with its length (export: per round).
    let stalled = null;
    video.addEventListener("waiting", () => {
      if (stalled === null) stalled = { at: video.currentTime, since: now(), round: roundOf() };
    });
    const endStall = (how) => {
      if (stalled === null) return;
      const s = stalled;
      stalled = null;
      log("video_stall", { video: label, at: s.at, seconds: Math.round((now() - s.since) * 1000) / 1000, how }, s.round);
    };
    video.addEventListener("playing", () => endStall("resumed"));
    video.addEventListener("emptied", () => endStall("replaced")); // the next round's video
  }

  // Play a video again from its start. A video sent while it was still being drawn cannot be
  // seeked (the browser got it without a length): it is fetched again, whole now.
  function restart(video) {
    const s = video.seekable;
    if (s.length > 0 && s.end(s.length - 1) > 0) {
      video.currentTime = 0;
    } else {
      video.src = video.src;
    }
    return video.play().catch(() => {});
  }

  // Common routing: leave a round page when the session is over.
  function routeFinished(s) {
    if (["finished", "failed", "cancelled"].includes(s.status)) {
      goTo("/done");
      return true;
    }
    return false;
  }

  // A video fetched whole into memory before it may play: once it is on the page nothing can
  // stall, and the stop time is read from a video that is all there. The server says when a file
  // is written whole (the state's `complete`); until then this waits. onProgress(share) as it loads.
  async function loadWhole(video, url, complete, onProgress) {
    const started = now();
    while (!(await complete())) await new Promise((r) => setTimeout(r, 250));
    const res = await fetch(url, { credentials: "same-origin" });
    if (!res.ok) throw new Error(`video ${url}: HTTP ${res.status}`);
    const total = Number(res.headers.get("content-length")) || 0;
    const parts = [];
    let got = 0;
    const reader = res.body.getReader();
    for (;;) {
      const { done, value } = await reader.read();
      if (done) break;
      parts.push(value);
      got += value.length;
      if (total) onProgress(Math.min(1, got / total));
    }
    const type = res.headers.get("content-type") || "video/webm";
    if (video.dataset.blob) URL.revokeObjectURL(video.dataset.blob);
    const blobUrl = URL.createObjectURL(new Blob(parts, { type }));
    video.dataset.blob = blobUrl;
    video.dataset.url = url; // which file it is (the element's own src is the blob)
    const loaded = new Promise((resolve, reject) => {
      video.addEventListener("loadeddata", resolve, { once: true });
      video.addEventListener("error", () => reject(new Error(`video ${url} cannot be decoded`)), { once: true });
    });
    video.src = blobUrl;
    video.load();
    await loaded;
    return { bytes: got, seconds: Math.round((now() - started) * 1000) / 1000 };
  }

  // Whether the video at `url` is written whole, from the session's state.
  const isComplete = (url) => async () => {
    const s = await api("GET", `/api/sessions/${sessionId}`);
    const videos = [...((s.question && s.question.videos) || []), ...(s.final_video ? [s.final_video] : [])];
    const v = videos.find((x) => x.url === url);
    return !v || v.complete !== false;
  };

  // H.264 MP4 where the browser plays it (every common one, Safari included), else the WebM.
  const H264 = 'video/mp4; codecs="avc1.42E01E"';
  function pickUrl(video, v) {
    return v.mp4_url && video.canPlayType(H264) ? v.mp4_url : v.url;
  }

  // Load every video of a gate whole (items: {video, v} with v the state's video), showing the
  // share loaded on the gate's button.
  async function loadForGate(gate, items, round) {
    const button = gate.querySelector("button");
    const label = button.firstChild;
    const text = label.textContent;
    const shares = items.map(() => 0);
    const show = () => {
      const pct = Math.round((100 * shares.reduce((a, b) => a + b, 0)) / items.length);
      label.textContent = `Loading ${pct} %`;
    };
    show();
    try {
      const urls = items.map((it) => pickUrl(it.video, it.v));
      const got = await Promise.all(items.map((it, i) => loadWhole(it.video, urls[i], isComplete(it.v.url),
        (share) => { shares[i] = share; show(); })));
      log("videos_loaded", { urls, bytes: got.map((g) => g.bytes), seconds: got.map((g) => g.seconds) }, round);
    } catch (err) {
      // the WebM played as it arrives instead: the stall log then says what the participant saw
      log("videos_load_failed", { error: String(err && err.message) }, round);
      for (const it of items) { it.video.src = it.v.url; it.video.dataset.url = it.v.url; it.video.load(); }
    } finally {
      label.textContent = text;
    }
  }

  // The ready gate before a video: nothing plays until the participant presses Ready (or Enter),
  // and Ready enables only once `loading` (the gate's videos, loaded whole) has settled.
  // onReady runs once; the gate logs how it was passed and tells the server (video "ready").
  function readyGate(gate, round, onReady, loading = Promise.resolve()) {
    const button = gate.querySelector("button");
    gate.classList.remove("hidden");
    button.disabled = true;
    let open = false;
    loading.finally(() => {
      open = true;
      button.disabled = false;
      button.focus();
    });
    const go = (via) => {
      if (!open) return;
      button.onclick = null;
      document.removeEventListener("keydown", onKey, true);
      button.disabled = true;
      gate.classList.add("hidden");
      log("ready", { via }, round);
      if (round !== null) reportVideo(round, "ready", 0);
      onReady();
    };
    const onKey = (e) => {
      if (e.key !== "Enter" || e.repeat) return;
      e.preventDefault();
      e.stopImmediatePropagation(); // not also an answer key
      go("key");
    };
    button.onclick = () => go("click");
    document.addEventListener("keydown", onKey, true);
  }

  // What happened to the round's video, for the server's own check of stop answers.
  function reportVideo(round, event, mediaTime) {
    const body = { round, event, client_ts: now() };
    if (typeof mediaTime === "number" && Number.isFinite(mediaTime)) body.media_time = mediaTime;
    return api("POST", `/api/sessions/${sessionId}/video`, body);
  }

  // The answer buttons in this participant's order (counterbalanced, see session.button_order).
  function orderButtons(container, attr, order) {
    for (const key of order || []) {
      const b = container.querySelector(`button[${attr}="${key}"]`);
      if (b) container.append(b);
    }
  }

  // Keys typed into a form field are not shortcuts.
  function isTyping(e) {
    const t = e.target;
    return t && (t.tagName === "INPUT" || t.tagName === "TEXTAREA" || t.isContentEditable);
  }

  return {
    sessionId, now, api, log, flush, goTo, poll, setProgress, fillGuess, setEstimate, setWaiting, showFatal,
    watchVideo, routeFinished, isTyping, setupLegend, fillLegend, describeVideo, betweenRounds,
    readyGate, loadForGate, reportVideo, orderButtons, restart, friendly,
  };
})();
