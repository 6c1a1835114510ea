// The ward page's live feed: server-sent events swap in the HTML the server rendered, and an
// alert not seen before plays a tone (generated here with Web Audio: no file, no network) and
// shows a browser notification. The tone repeats while any alert is open and unacknowledged.
"use strict";
(function () {
  const csrf = document.querySelector('meta[name="csrf"]').content;
  const withCsrf = (html) => html.split("__CSRF__").join(csrf);
  const station = (window.station = { seen: new Set(), notified: [], sounding: false, beeps: 0 });
  let audio = null;
  let timer = null;

  document.addEventListener("submit", (event) => {
    const button = event.submitter;
    if (button && button.dataset.confirm && !window.confirm(button.dataset.confirm)) event.preventDefault();
  });

  const alertsList = document.getElementById("alerts");
  if (!alertsList) return; // only the ward page listens

  function beep() {
    station.beeps += 1;
    if (!audio) return;
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

  function notify(id, text) {
    station.notified.push(id);
    if ("Notification" in window && Notification.permission === "granted") {
      try { new Notification("Ward station: " + text, { tag: "alert-" + id, requireInteraction: true }); }
      catch (e) { /* some browsers only allow notifications from a service worker */ }
    }
  }

  function showAlerts(data) {
    alertsList.innerHTML = withCsrf(data.html);
    document.getElementById("no-alerts").hidden = data.ids.length > 0;
    for (const alert of data.alerts) {
      if (!station.seen.has(alert.id)) { station.seen.add(alert.id); notify(alert.id, alert.text); }
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
    else document.getElementById("kiosks").appendChild(tile);
  }

  // offline and "seconds ago" follow the clock between reports, corrected for the server's clock
  const kiosks = document.getElementById("kiosks");
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

  document.getElementById("enable-sound").addEventListener("click", (event) => {
    audio = audio || new (window.AudioContext || window.webkitAudioContext)();
    audio.resume();
    if ("Notification" in window && Notification.permission === "default") Notification.requestPermission();
    event.target.textContent = "Sound and notifications on";
    event.target.disabled = true;
    if (station.sounding) beep();
  });

  for (const li of alertsList.querySelectorAll("[data-alert-id]")) station.seen.add(Number(li.dataset.alertId));
  setSounding(station.seen.size > 0);

  const source = new EventSource("/events");
  source.addEventListener("alerts", (e) => showAlerts(JSON.parse(e.data)));
  source.addEventListener("kiosk", (e) => showKiosk(JSON.parse(e.data)));
  source.addEventListener("resync", () => window.location.reload());
  source.addEventListener("open", () => { document.body.dataset.live = "1"; });
  source.addEventListener("error", () => { document.body.dataset.live = "0"; });
})();
