// Start page. Step 1 (no session yet): the consent text of the study file and the participant
// ID from the link (?pid= or Prolific's PROLIFIC_PID, STUDY_ID, SESSION_ID), or a typed code.
// Agreeing enrols the participant (a session that does not run yet, with its key) and reloads
// as /?session=…, step 2: what to do, for the condition this participant will get. Only Start
// starts the session's episode (and takes one of the server's slots).
"use strict";

(async () => {
  const $ = (id) => document.getElementById(id);
  const params = new URLSearchParams(location.search);
  const ID_PATTERN = /^[A-Za-z0-9_-]{1,64}$/; // as the server checks (web/study.py)

  if (Study.sessionId) return showHow();

  let config;
  try {
    config = await Study.api("GET", "/api/config");
  } catch (err) {
    Study.showFatal("The study server cannot be reached. Please check your connection and reload this page.");
    return;
  }
  $("step-enter").classList.remove("hidden");
  const pid = params.get("PROLIFIC_PID") ?? params.get("pid");
  const ids = { pid, study_id: params.get("STUDY_ID"), prolific_session_id: params.get("SESSION_ID") };
  const names = { pid: "participant ID", study_id: "STUDY_ID", prolific_session_id: "SESSION_ID" };
  const bad = Object.keys(ids).filter((k) => ids[k] !== null && !ID_PATTERN.test(ids[k]));
  if (bad.length) {
    Study.showFatal(`This link's ${bad.map((k) => names[k]).join(" and ")} is not valid (1 to 64 letters, ` +
      "digits, '_' or '-'). Please open the link you were given again, or contact the researchers.");
    return;
  }
  // A study that needs a participant ID and a link without one: the participant types it
  // (checked as the link's would be); otherwise the code field is optional free text.
  const typedPid = config.require_pid && pid === null;
  const field = $("participant");
  if (typedPid) {
    $("participant-label").textContent = "Your participant ID (required)";
    field.maxLength = 64;
    field.setAttribute("aria-required", "true");
  }
  const typedOk = () => !typedPid || ID_PATTERN.test(field.value.trim());
  if (pid !== null) {
    $("pid-value").textContent = pid;
    $("pid-line").classList.remove("hidden");
    $("code-field").classList.add("hidden");
  }
  const begin = $("begin");
  if (config.consent) {
    const box = $("consent-text");
    for (const para of config.consent.split(/\n\s*\n/)) {
      const p = document.createElement("p");
      p.textContent = para.trim();
      box.append(p);
    }
    $("consent").classList.remove("hidden");
    begin.textContent = "I agree, continue";
    $("decline").classList.remove("hidden");
    $("decline").addEventListener("click", () => {
      $("step-enter").classList.add("hidden");
      $("declined").classList.remove("hidden");
    });
  }
  begin.disabled = !typedOk();
  field.addEventListener("input", () => {
    begin.disabled = !typedOk();
    $("status").textContent = typedPid && field.value.trim() && !typedOk()
      ? "A participant ID has 1 to 64 letters, digits, '_' or '-'." : "";
    $("status").classList.remove("error");
  });
  field.addEventListener("keydown", (e) => {
    if (e.key === "Enter" && !begin.disabled) begin.click();
  });
  begin.addEventListener("click", async () => {
    if (!typedOk()) return;
    begin.disabled = true;
    $("status").textContent = "Starting…";
    const body = {};
    for (const [k, v] of Object.entries(ids)) if (v !== null) body[k] = v;
    if (typedPid) body.pid = field.value.trim();
    else if (pid === null) body.participant = field.value.trim() || null;
    if (config.consent) body.consent = true;
    body.start = false; // the episode starts at Start, not here
    try {
      const s = await Study.api("POST", "/api/sessions", body);
      location.href = `/?session=${encodeURIComponent(s.id)}`;
    } catch (err) {
      Study.showFatal(Study.friendly(err));
      begin.disabled = false;
    }
  });

  async function showHow() {
    let s;
    try {
      s = await Study.api("GET", `/api/sessions/${Study.sessionId}`);
    } catch (err) {
      Study.showFatal(Study.friendly(err));
      return;
    }
    if (!["enrolled", "waiting-for-learner", "waiting-for-answer"].includes(s.status)) return Study.goTo("/done");
    $("step-how").classList.remove("hidden");
    // the signal's own instructions (a fragment from the signal's folder, as trusted as its page)
    const how = await fetch(`${s.page}/how`, { cache: "no-store" });
    if (how.ok) {
      $("how").innerHTML = await how.text();
      $("how").classList.remove("hidden");
    }
    if (s.design === "assigned-rule") {
      $("rule-text").textContent = s.intention_description;
      $("rule-assigned").classList.remove("hidden");
    } else {
      $("rule-free").classList.remove("hidden");
    }
    $("guess-note").textContent = {
      "always": "From the second round on, the page shows the robot's current guess of your rule.",
      "after-answer": "After each of your answers, the page shows what the robot now guesses, before the next round.",
    }[s.show_estimate] || "";
    $("rounds").textContent = `There are ${s.rounds} rounds; each takes under a minute.`;
    Study.log("page_load", { page: "start" });
    Study.poll(() => {}); // keeps the session from going idle while the participant reads
    const start = $("start");
    start.disabled = false;
    start.addEventListener("click", async () => {
      Study.log("start_clicked");
      start.disabled = true;
      $("status-how").textContent = "Starting…";
      $("status-how").classList.remove("error");
      try {
        if (s.status === "enrolled") await Study.api("POST", `/api/sessions/${Study.sessionId}/start`);
        Study.goTo(s.page);
      } catch (err) {
        Study.log("start_refused", { status: err.status ?? null, code: err.code ?? null });
        $("status-how").textContent = Study.friendly(err);
        $("status-how").classList.add("error");
        start.disabled = false;
      }
    });
  }
})();
