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
  addEventListener("pagehide", flushNow);
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
        const key = `${s.status}|${s.question ? s.question.round : "-"}|${s.phase}|${s.estimate}`;
        if (key !== last) {
          last = key;
          onState(s);
        }
      } catch (err) {
        showFatal(err.status === 404 ? "This session does not exist (or the server was restarted)." : `Lost contact with the server: ${err.message}`);
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
    el.querySelector(".bar span").style.width = `${100 * (done ? 1 : (s.progress - 1) / s.rounds)}%`;
  }

  function setEstimate(s) {
    const box = document.getElementById("estimate");
    if (!box) return;
    box.classList.toggle("hidden", !s.estimate);
    box.querySelector("span").textContent = s.estimate || "";
  }

  function setWaiting(shown, text) {
    const w = document.getElementById("waiting");
    const q = document.getElementById("question");
    if (text) w.querySelector("p").textContent = text;
    w.classList.toggle("shown", shown);
    q.classList.toggle("hidden", shown);
  }

  function showFatal(msg) {
    const el = document.getElementById("status");
    if (el) { el.textContent = msg; el.classList.add("error"); }
  }

  // Log what the participant does with a video (play, pause, seeks, ends).
  function watchVideo(video, label, roundOf) {
    for (const type of ["loadedmetadata", "play", "playing", "pause", "seeked", "ended", "error"]) {
      video.addEventListener(type, () =>
        log(`video_${type}`, { video: label, time: video.currentTime, duration: video.duration }, roundOf()));
    }
  }

  // Common routing: leave a round page when the session is over.
  function routeFinished(s) {
    if (["finished", "failed", "cancelled"].includes(s.status)) {
      goTo("/done");
      return true;
    }
    return false;
  }

  // Keys typed into a form field are not shortcuts.
  function isTyping(e) {
    const t = e.target;
    return t && (t.tagName === "INPUT" || t.tagName === "TEXTAREA" || t.isContentEditable);
  }

  return { sessionId, now, api, log, flush, goTo, poll, setProgress, setEstimate, setWaiting, showFatal, watchVideo, routeFinished, isTyping };
})();
