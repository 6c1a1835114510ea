// Every station page listens to the live feed (server-sent events): the ward page swaps in the
// HTML the server rendered; on any page an alert not seen before, or a result that just arrived,
// plays a tone (Web Audio: no file, no network) and shows a browser notification, and the
// navigation's count of results waiting follows. An open alert's tone repeats until it closes.
//
// Sound stays on for the shift: the choice is kept in localStorage, the ward page's actions are
// sent without leaving the page (fetch), and on any other page load the audio, which a browser
// only starts after a touch, is resumed by the first touch or key anywhere on the page.
"use strict";
(function () {
  const csrfMeta = document.querySelector('meta[name="csrf"]');
  const csrf = csrfMeta ? csrfMeta.content : "";
  const withCsrf = (html) => html.split("__CSRF__").join(csrf);
  const station = (window.station = {
    seen: new Set(), rung: new Set(), notified: [], sounding: false, beeps: 0, audible: 0,
  });
  const SOUND = "station.sound";
  let audio = null;
  let timer = null;

  // -- the print views: their button opens the browser's print dialog (print or save as PDF) --
  document.addEventListener("click", (event) => {
    const target = event.target instanceof Element ? event.target.closest("[data-print]") : null;
    if (target) window.print();
  });

  // -- confirmations and actions that stay on the page ---------------------------------------
  document.addEventListener("submit", (event) => {
    const button = event.submitter;
    if (button && button.dataset.confirm && !window.confirm(button.dataset.confirm)) {
      event.preventDefault();
      return;
    }
    const form = event.target;
    if (!form.hasAttribute("data-fetch")) return;
    event.preventDefault();
    const body = new URLSearchParams(new FormData(form));
    fetch(form.action, { method: "POST", body, credentials: "same-origin" })
      .then((response) => response.text().then((text) => [response, text]))
      .then(([response, text]) => {
        const page = new DOMParser().parseFromString(text, "text/html");
        const said = page.querySelector(".message");
        say(said ? said.textContent : response.ok ? "" : text.slice(0, 200));
      })
      .catch(() => say("The station did not answer: try again."));
  });

  function say(text) {
    let box = document.getElementById("action-message");
    if (!box) {
      box = document.createElement("p");
      box.id = "action-message";
      box.className = "message";
      box.setAttribute("role", "status");
      document.querySelector("main").before(box);
    }
    box.textContent = text;
    box.hidden = !text;
  }

  const button = document.getElementById("enable-sound");
  if (!button) return; // not logged in: nothing to listen to

  // -- sound ------------------------------------------------------------------------------------
  const wanted = () => window.localStorage.getItem(SOUND) === "on";
  const playing = () => audio !== null && audio.state === "running";

  function arm() {
    if (!audio) {
      audio = new (window.AudioContext || window.webkitAudioContext)();
      audio.addEventListener("statechange", showSound);
    }
    if (audio.state !== "running") audio.resume().then(showSound, showSound);
    showSound();
  }

  function showSound() {
    const state = !wanted() ? "off" : playing() ? "on" : "paused";
    document.body.dataset.sound = state;
    button.textContent = {
      off: "Turn on sound and notifications",
      on: "Sound on (tap to turn off)",
      paused: "Sound paused: tap anywhere to resume",
    }[state];
  }

  button.addEventListener("click", (event) => {
    event.stopPropagation();
    if (wanted() && playing()) {
      window.localStorage.setItem(SOUND, "off");
      audio.suspend();
      showSound();
      return;
    }
    window.localStorage.setItem(SOUND, "on");
    arm();
    if ("Notification" in window && Notification.permission === "default") Notification.requestPermission();
    if (station.sounding) beep();
  });
  // a browser starts audio only after a gesture on this page: the first touch or key resumes it
  for (const kind of ["pointerdown", "keydown"]) {
    document.addEventListener(kind, () => { if (wanted() && !playing()) arm(); }, { capture: true });
  }
  if (wanted()) arm();
  showSound();

  function beep() {
    station.beeps += 1;
    document.body.dataset.beeps = String(station.beeps);
    if (!playing()) return;
    station.audible += 1;
    document.body.dataset.audible = String(station.audible);
    const now = audio.currentTime;
    for (const [start, freq] of [[0, 880], [0.25, 660]]) {
      const osc = audio.createOscillator();
      const gain = audio.createGain();
      osc.frequency.value = freq;
      gain.gain.setValueAtTime(0.0001, now + start);
      gain.gain.exponentialRampToValueAtTime(0.4, now + start + 0.02);
      gain.gain.exponentialRampToValueAtTime(0.0001, now + start + 0.22);
      osc.connect(gain).connect(audio.destination);
      osc.start(now + start);
      osc.stop(now + start + 0.25);
    }
  }

  function setSounding(on) {
    station.sounding = on;
    document.body.dataset.sounding = on ? "1" : "0";
    if (on && !timer) { beep(); timer = setInterval(beep, 4000); }
    if (!on && timer) { clearInterval(timer); timer = null; }
  }

  function notify(tag, text, href) {
    station.notified.push(tag);
    if ("Notification" in window && Notification.permission === "granted") {
      try {
        const shown = new Notification("Ward station: " + text, { tag, requireInteraction: true });
        if (href) shown.onclick = () => { window.focus(); window.location.href = href; };
      } catch (e) { /* some browsers only allow notifications from a service worker */ }
    }
  }

  // -- the live feed ------------------------------------------------------------------------------
  const alertsList = document.getElementById("alerts");

  function showAlerts(data) {
    if (alertsList) {
      alertsList.innerHTML = withCsrf(data.html);
      document.getElementById("no-alerts").hidden = data.ids.length > 0;
    }
    for (const alert of data.alerts) {
      if (!station.seen.has(alert.id)) { station.seen.add(alert.id); notify("alert-" + alert.id, alert.text, "/"); }
    }
    setSounding(data.ids.length > 0);
  }

  function showKiosk(data) {
    const old = document.getElementById("kiosk-" + data.name);
    const box = document.createElement("div");
    box.innerHTML = withCsrf(data.html);
    const tile = box.firstElementChild;
    if (!tile) return;
    if (old) old.replaceWith(tile);
    else if (document.getElementById("kiosks")) document.getElementById("kiosks").appendChild(tile);
  }

  function refill(id, url) {
    const target = document.getElementById(id);
    if (!target) return;
    fetch(url, { credentials: "same-origin" })
      .then((response) => (response.ok ? response.text() : Promise.reject(response.status)))
      .then((html) => { target.innerHTML = html; target.dataset.filled = String(Date.now()); })
      .catch(() => {});
  }

  // a part of the page that follows what changed (an order's state): the page's own HTML again,
  // that part swapped in place, so nothing reloads (and the sound stays on)
  function refresh(part) {
    fetch(window.location.href, { credentials: "same-origin" })
      .then((response) => (response.ok ? response.text() : Promise.reject(response.status)))
      .then((html) => {
        const fresh = new DOMParser().parseFromString(html, "text/html").getElementById(part.id);
        if (fresh && fresh.innerHTML !== part.innerHTML) part.innerHTML = fresh.innerHTML;
      })
      .catch(() => {});
  }

  function showResults(data) {
    const count = document.getElementById("waiting-count");
    count.textContent = String(data.count);
    count.classList.toggle("some", data.count > 0);
    for (const result of data.rung) {
      if (station.rung.has(result.session)) continue;
      station.rung.add(result.session);
      notify("result-" + result.session, result.text, result.href);
      beep();
    }
    refill("results", "/fragments/results");
    for (const part of document.querySelectorAll("[data-refresh]")) refresh(part);
    const inbox = document.getElementById("inbox");
    if (inbox) {
      refill("inbox", "/fragments/inbox?" + new URLSearchParams({ state: inbox.dataset.state, kiosk: inbox.dataset.kiosk, after: inbox.dataset.after || "" }));
    }
  }

  // offline and "seconds ago" follow the clock between reports, corrected for the server's clock
  const kiosks = document.getElementById("kiosks");
  if (kiosks) {
    const skew = Date.now() / 1000 - parseFloat(kiosks.dataset.serverNow);
    const offlineAfter = parseFloat(kiosks.dataset.offlineAfter);
    setInterval(() => {
      const now = Date.now() / 1000 - skew;
      for (const tile of kiosks.querySelectorAll(".tile")) {
        const seen = parseFloat(tile.dataset.lastSeen);
        if (!seen) continue;
        const offline = now - seen > offlineAfter;
        tile.classList.toggle("offline", offline);
        const state = tile.querySelector(".state");
        if (state && state.textContent !== "token revoked") state.textContent = offline ? "offline" : "online";
        const ago = tile.querySelector(".ago");
        if (ago) ago.textContent = Math.max(0, Math.round(now - seen)) + " s ago";
      }
    }, 1000);
  }

  if (alertsList) {
    for (const li of alertsList.querySelectorAll("[data-alert-id]")) station.seen.add(Number(li.dataset.alertId));
    setSounding(station.seen.size > 0);
  }

  const source = new EventSource("/events");
  source.addEventListener("alerts", (e) => showAlerts(JSON.parse(e.data)));
  source.addEventListener("kiosk", (e) => showKiosk(JSON.parse(e.data)));
  source.addEventListener("results", (e) => showResults(JSON.parse(e.data)));
  source.addEventListener("resync", () => {
    refill("results", "/fragments/results");
    if (alertsList) window.location.reload();
  });
  source.addEventListener("open", () => { document.body.dataset.live = "1"; });
  source.addEventListener("error", () => { document.body.dataset.live = "0"; });
})();
