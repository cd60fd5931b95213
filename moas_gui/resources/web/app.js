/* The MOAS browser client: the client protocol over a WebSocket (docs/web-client.md).
   It shows only what the server says and sends every wish as a request; the
   server decides what a tap selects.  No frameworks, no build step. */
"use strict";

(() => {
  const LONG_PRESS_MS = 550;
  const REQUEST_TIMEOUT_MS = 5000;
  const QUIET_MS = 15000;          // ask for the state when the server was silent this long
  const KEEPALIVE_MS = 30000;      // say something this often: the server closes a silent page
  const $ = (sel, root = document) => root.querySelector(sel);

  const params = new URLSearchParams(location.search);
  const saved = JSON.parse(localStorage.getItem("moas") || "{}");
  const choice = {
    station: num(params.get("station")) ?? saved.station ?? null,
    radios: [num(params.get("radio")) ?? saved.radioA ?? null,
             params.has("radio2") ? num(params.get("radio2")) : (saved.radioB ?? null)],
    active: 0,
  };
  function num(text) { const n = Number.parseInt(text ?? "", 10); return Number.isFinite(n) ? n : null; }
  function save() {
    localStorage.setItem("moas", JSON.stringify(
      { station: choice.station, radioA: choice.radios[0], radioB: choice.radios[1] }));
  }

  // an operator's token: from a pairing QR code's fragment (#token=...), kept in this
  // browser, sent in hello; never in the address bar after it is read
  const TOKEN_KEY = "moas-token";
  function tokenFromFragment() {
    const fragment = new URLSearchParams(location.hash.slice(1));
    if (!fragment.get("token")) return false;
    localStorage.setItem(TOKEN_KEY, fragment.get("token"));
    history.replaceState(null, "", location.pathname + location.search);
    return true;
  }
  tokenFromFragment();
  window.addEventListener("hashchange", () => {  // a pairing link opened on this page
    if (tokenFromFragment()) { $("#signin").hidden = true; if (ws) ws.close(); else connect(); }
  });
  function askToken(why) {
    const box = $("#signin");
    $(".why", box).textContent = why;
    box.hidden = false;
    $("#token").focus();
  }
  // a station's words to an operator (never the protocol's), as the desktop client says them
  const TOKEN_ASKED = "This station asks for an operator's token: ask its admin, or scan its pairing code.";
  const TOKEN_REFUSED = "This station did not take that token (it may have been removed): " +
    "ask its admin for a new one, or scan its pairing code.";
  function tokenOf(text) {  // a pasted pairing link gives its token; anything else is the token
    if (!text.includes("://")) return text;
    try { return new URLSearchParams(new URL(text).hash.slice(1)).get("token") || ""; }
    catch { return ""; }
  }
  function takeToken() {
    const text = tokenOf($("#token").value.trim());
    if (!text) { $(".why", $("#signin")).textContent = TOKEN_ASKED; return; }
    localStorage.setItem(TOKEN_KEY, text);
    $("#token").value = "";
    $("#signin").hidden = true;
    if (ws) ws.close(); else connect();
  }
  $("#token-go").addEventListener("click", takeToken);
  $("#token").addEventListener("keydown", e => { if (e.key === "Enter") takeToken(); });

  // the contest report: fetched with this browser's token in the Authorization header
  // (never in an address the server logs) and shown here; its charts become images
  // (this page's policy allows no inline style, an image's own document may have it)
  async function showReport(event) {
    event.preventDefault();
    const body = $("#report-body");
    body.textContent = "Making the report\u2026";
    $("#report").hidden = false;
    document.body.classList.add("reading");
    const token = localStorage.getItem(TOKEN_KEY);
    try {
      const answer = await fetch("/report", { cache: "no-store",
        headers: token ? { Authorization: "Bearer " + token } : {} });
      const text = await answer.text();
      if (answer.status === 401) body.textContent = token ? TOKEN_REFUSED : TOKEN_ASKED;
      else if (!answer.ok) body.textContent = text.trim() || "The report could not be made.";
      else showReportPage(body, text);
    } catch (e) {
      body.textContent = "The report could not be fetched: " + e.message;
    }
  }
  function showReportPage(body, text) {
    const doc = new DOMParser().parseFromString(text, "text/html");
    const shown = [];
    for (const node of doc.body.children) {
      if (node.tagName === "H1" || node.tagName === "FOOTER") continue;
      const svg = node.tagName === "FIGURE" ? node.querySelector("svg") : null;
      if (node.tagName === "FIGURE" && !svg) continue;
      if (!svg) { shown.push(document.importNode(node, true)); continue; }
      const figure = document.createElement("figure");
      const image = document.createElement("img");
      image.alt = svg.querySelector("title") ? svg.querySelector("title").textContent : node.id;
      image.src = "data:image/svg+xml;charset=utf-8," +
        encodeURIComponent(new XMLSerializer().serializeToString(svg));
      figure.id = "report-" + node.id;
      figure.append(image);
      shown.push(figure);
    }
    body.replaceChildren(...shown);
  }
  function hideReport() {
    $("#report").hidden = true;
    document.body.classList.remove("reading");
  }
  $("#report-link").addEventListener("click", showReport);
  $("#report-back").addEventListener("click", hideReport);
  document.addEventListener("keydown", e => { if (e.key === "Escape" && !$("#report").hidden) hideReport(); });

  let ws = null, connected = false, snapshot = null, nextId = 1, retry = 500, lastHeard = 0, lastSent = 0;
  let firstState = true;
  let operator = null;  // who this page acts as, from hello's result (null: anonymous)
  const pending = new Map();
  const panels = [];

  // -- the connection ----------------------------------------------------------------------------
  function connect() {
    const scheme = location.protocol === "https:" ? "wss://" : "ws://";
    const socket = new WebSocket(scheme + location.host + "/ws");
    ws = socket;
    socket.onopen = () => {
      retry = 500;
      const hello = { cmd: "hello", client: "browser " + shortAgent() };
      if (choice.station != null) hello.station = choice.station;
      if (choice.radios[0] != null) hello.radio = choice.radios[0];
      const token = localStorage.getItem(TOKEN_KEY);
      if (token) hello.token = token;
      request(hello).then(result => {
        operator = result && result.operator ? result.operator : null;
        for (const p of panels) showRadio(p);
      }).catch(e => {
        showLink(false, e.code === "forbidden" ? "waiting for an operator's token" : e.message);
        // too many wrong tokens lately (anyone's): the token was not checked; try it again then
        const later = /try again in (\d+) s/.exec(e.message);
        if (e.code === "forbidden" && token && later) {
          showLink(false, e.message);
          setTimeout(() => { if (ws === socket) socket.close(); }, Number(later[1]) * 1000);
        } else if (e.code === "forbidden") {
          if (token) localStorage.removeItem(TOKEN_KEY);
          askToken(token ? TOKEN_REFUSED : TOKEN_ASKED);
        }
      });
    };
    socket.onmessage = (e) => {
      lastHeard = Date.now();
      let msg;
      try { msg = JSON.parse(e.data); } catch { return; }
      if (msg.event) onEvent(msg);
      else if (pending.has(msg.id)) {
        const p = pending.get(msg.id);
        pending.delete(msg.id);
        clearTimeout(p.timer);
        if (msg.ok) p.resolve(msg.result);
        else {
          const error = new Error(msg.error ? msg.error.message : "refused");
          error.code = msg.error ? msg.error.code : null;
          p.reject(error);
        }
      }
    };
    socket.onclose = () => {
      if (ws !== socket || parked) return;
      ws = null;
      connected = false;
      for (const p of pending.values()) { clearTimeout(p.timer); p.reject(new Error("not connected")); }
      pending.clear();
      showLink(false);
      if (!$("#signin").hidden) return;  // no token yet: wait for one
      setTimeout(connect, retry + Math.random() * 250);
      retry = Math.min(retry * 2, 4000);
    };
  }

  function request(obj) {
    return new Promise((resolve, reject) => {
      if (!ws || ws.readyState !== WebSocket.OPEN) { reject(new Error("not connected")); return; }
      const id = nextId++;
      const timer = setTimeout(() => {
        pending.delete(id);
        reject(new Error("the server did not answer"));
        if (ws) ws.close();
      }, REQUEST_TIMEOUT_MS);
      pending.set(id, { resolve, reject, timer });
      ws.send(JSON.stringify({ id, ...obj }));
      lastSent = Date.now();
    });
  }

  setInterval(() => {  // a silent server is asked; one that does not answer is left
    if (connected && Date.now() - lastHeard > QUIET_MS) request({ cmd: "state" }).then(onState, () => {});
    else if (connected && ws && Date.now() - lastSent > KEEPALIVE_MS) {  // an empty message: a blank line
      ws.send("");
      lastSent = Date.now();
    }
  }, 5000);

  function shortAgent() {
    const m = navigator.userAgent.match(/(Android|iPad|iPhone|Windows|Mac OS X|Linux)/);
    return m ? m[1] : "page";
  }

  // -- events ------------------------------------------------------------------------------------
  function onEvent(msg) {
    switch (msg.event) {
      case "state": onState(msg); break;
      case "radio": replace(snapshot && snapshot.radios, msg, r => r.station === msg.station && r.radio === msg.radio);
        for (const p of panels) if (p.radio === msg.radio && choice.station === msg.station) { showRadio(p); showCompass(p); }
        break;
      case "rotator": replace(snapshot && snapshot.rotators, msg, r => r.id === msg.id);
        for (const p of panels) showCompass(p);
        break;
      case "switch": replace(snapshot && snapshot.switches, msg, s => s.id === msg.id);
        showLink(true); for (const p of panels) { showRadio(p); showCompass(p); }
        break;
      case "layout":
        for (const p of panels) {
          if (p.asked && p.asked.station === msg.station && p.asked.radio === msg.radio &&
              p.shape && p.shape[0] === msg.rows && p.shape[1] === msg.columns) showLayout(p, msg);
        }
        break;
      default: break;
    }
  }

  function replace(list, entry, same) {
    if (!list) return;
    const clean = { ...entry }; delete clean.event;
    const i = list.findIndex(same);
    if (i >= 0) list[i] = clean; else list.push(clean);
  }

  function onState(state) {
    snapshot = { ...state }; delete snapshot.event;
    connected = true;
    for (const p of panels) clearMessage(p);  // a fresh state for everyone: old answers are old
    $("#config").textContent = snapshot.config || "no configuration";
    fillChoices();
    showLink(true);
    for (const p of panels) p.asked = null;
    buildPanels();
    if (firstState && snapshot.radios.length) {
      firstState = false;
      if (window.performance && performance.mark) performance.mark("moas-first-state");
    }
  }

  /* The table of screen states, the same as the desktop client's
     (moas_gui/client/screen.py; docs/client.md "What the window shows when"). */
  function screenState() {
    if (!connected || !snapshot) return "reconnecting";
    if (!snapshot.config) return "no configuration";
    const switches = snapshot.switches || [];
    if (switches.length && switches.every(s => s.status === "stopped")) return "switches stopped";
    if (switches.some(s => s.status === "unresponsive" || s.status === "connecting")) return "switch unresponsive";
    return "connected";
  }
  function stopped() { return screenState() === "switches stopped"; }
  function showsSelection() { const s = screenState(); return s === "connected" || s === "switch unresponsive"; }
  const REFUSALS = {
    "reconnecting": "not connected to the server; the page keeps trying",
    "no configuration": "the server has no configuration open",
    "switches stopped": "the switches are stopped; start them on the server (File > Start Switches)",
  };

  function showLink(up, detail) {
    const link = $("#link");
    const state = up ? screenState() : "reconnecting";
    document.body.classList.toggle("offline", !up);
    document.body.classList.toggle("stopped", up && state === "switches stopped");
    if (!up) {
      link.className = "link down";
      link.textContent = "\u2715 Not connected \u2013 " + (detail || "reconnecting\u2026");
    } else if (state === "switches stopped") {
      link.className = "link stopped";
      link.textContent = "\u25a0 Switches stopped: all relays off";
    } else if (state === "no configuration") {
      link.className = "link stopped";
      link.textContent = "\u25cb Connected; the server has no configuration open";
    } else if (state === "switch unresponsive") {
      const which = snapshot.switches.filter(s => s.status === "unresponsive" || s.status === "connecting").map(s => s.id).join(", ");
      link.className = "link stopped";
      link.textContent = `\u25b2 Switch ${which} not answering: its relays may not match what is shown`;
    } else {
      link.className = "link up";
      link.textContent = "\u25cf Connected";
    }
    document.body.dataset.link = up ? "connected" : "not-connected";
    document.body.dataset.screen = state;
    for (const p of panels) {
      expireMessage(p);
      showRadio(p); if (p.layout) showLayout(p, p.layout); else showCompass(p);
    }
  }

  /* The status line under each radio's buttons follows the desktop client's table
     (docs/client.md "The status line"; moas_gui/client/screen.py StatusMessage): one
     message at a time, a warning (⚠) or an answer (ℹ), tied to the screen state and
     the radio it was shown in; a change of either, a fresh state or the next press
     clears it. */
  function say(p, text, tone) {
    const el = $(".message", p.el);
    p.message = { text, tone, screen: currentScreen(), radio: radioKey(p) };
    el.textContent = (tone === "warning" ? "\u26a0 " : "\u2139 ") + text;
    el.dataset.tone = tone;
    // a phone's reply lands where the finger is, not below the fold
    if (el.scrollIntoView) el.scrollIntoView({ block: "nearest" });
  }
  function clearMessage(p) {
    p.message = null;
    const el = $(".message", p.el);
    el.textContent = "";
    delete el.dataset.tone;
  }
  function expireMessage(p) {
    const m = p.message;
    if (m && (m.screen !== currentScreen() || m.radio !== radioKey(p))) clearMessage(p);
  }
  function radioKey(p) { return `${choice.station}/${p.radio}`; }
  // the link may be down before the socket says so: "reconnecting" then, whatever the snapshot
  function currentScreen() { return document.body.dataset.link === "connected" ? screenState() : "reconnecting"; }

  // -- choosing station and radios ---------------------------------------------------------------
  function fillChoices() {
    const stations = [...new Set(snapshot.radios.map(r => r.station))].sort((a, b) => a - b);
    if (!stations.includes(choice.station)) choice.station = stations.length ? stations[0] : null;
    const radios = snapshot.radios.filter(r => r.station === choice.station).map(r => r.radio).sort((a, b) => a - b);
    if (!radios.includes(choice.radios[0])) choice.radios[0] = radios.length ? radios[0] : null;
    if (choice.radios[1] != null && (!radios.includes(choice.radios[1]) || choice.radios[1] === choice.radios[0])) {
      choice.radios[1] = null;
    }
    fillSelect($("#station"), stations, choice.station, false);
    fillSelect($("#radioA"), radios, choice.radios[0], false);
    const others = radios.filter(r => r !== choice.radios[0]);
    fillSelect($("#radioB"), others, choice.radios[1], true);
    // a station with one radio has no second to show: no "and \u2013" selector
    $("#radioB").closest("label").hidden = others.length === 0;
  }

  function fillSelect(select, values, current, blank) {
    select.replaceChildren();
    if (blank) select.append(new Option("\u2013", ""));
    for (const v of values) select.append(new Option(String(v), String(v)));
    select.value = current == null ? "" : String(current);
  }

  $("#station").addEventListener("change", (e) => {
    choice.station = num(e.target.value); choice.radios = [null, null]; save(); fillChoices(); buildPanels();
  });
  $("#radioA").addEventListener("change", (e) => { choice.radios[0] = num(e.target.value); save(); fillChoices(); buildPanels(); });
  $("#radioB").addEventListener("change", (e) => { choice.radios[1] = num(e.target.value); save(); fillChoices(); buildPanels(); });

  // -- the radio panels --------------------------------------------------------------------------
  function buildPanels() {
    const wanted = choice.radios.filter(r => r != null);
    const main = $("#radios");
    while (panels.length > wanted.length) panels.pop().el.remove();
    wanted.forEach((radio, i) => {
      if (!panels[i]) panels.push(makePanel(i));
      const p = panels[i];
      if (p.radio !== radio) { p.radio = radio; p.asked = null; p.layout = null; p.rotator = null; }
      expireMessage(p);  // a message is about the station and radio it was shown for
      p.el.dataset.radio = String(radio);
      $(".title", p.el).textContent = `Station ${choice.station} \u00b7 Radio ${radio}`;
    });
    main.classList.toggle("two", panels.length === 2);
    const tabs = $("#tabs");
    tabs.classList.toggle("two", panels.length === 2);
    tabs.replaceChildren();
    if (choice.active >= panels.length) choice.active = 0;
    panels.forEach((p, i) => {
      p.el.classList.toggle("active", i === choice.active);
      const b = document.createElement("button");
      b.type = "button"; b.textContent = `Radio ${p.radio}`;
      b.setAttribute("aria-pressed", String(i === choice.active));
      b.addEventListener("click", () => { choice.active = i; buildPanels(); });
      tabs.append(b);
    });
    for (const p of panels) { showRadio(p); askLayout(p); showCompass(p); }
  }

  function makePanel(index) {
    const el = $("#panel").content.firstElementChild.cloneNode(true);
    $("#radios").append(el);
    const p = { index, el, radio: null, target: "both", asked: null, shape: null, layout: null, rotator: null, message: null };
    for (const b of el.querySelectorAll(".targets button")) {
      b.addEventListener("click", () => {
        p.target = b.dataset.target;
        for (const o of el.querySelectorAll(".targets button")) o.setAttribute("aria-pressed", String(o === b));
      });
    }
    // tapping the display line shows (or hides) why the radio has its antennas
    $(".display", el).addEventListener("click", () => {
      const why = $(".why", el);
      why.hidden = !why.hidden || !why.textContent;
    });
    const step = (by) => {  // no relative list here: answered on the page, nothing sent
      const r = radioView(p);
      if (showsSelection() && r && noRelative(r)) {
        say(p, `Relative: there is no relative antenna list at ${khzText(r.khz)}`, "info");
        return;
      }
      send(p, { cmd: "relative", step: by }, "Relative");
    };
    // a hold outlives the program that set it: an operator whose role covers the radio frees it
    $(".release", el).addEventListener("click", () => send(p, { cmd: "release" }, "Release"));
    $(".prev", el).addEventListener("click", () => step(-1));
    $(".next", el).addEventListener("click", () => step(1));
    $(".rotator", el).addEventListener("change", (e) => { p.rotator = num(e.target.value); p.picked = true; showCompass(p); });
    $(".stop", el).addEventListener("click", () => {
      if (!connected) { say(p, "Stop: " + REFUSALS.reconnecting, "warning"); return; }
      if (p.rotator != null) act(p, { cmd: "stop", rotator: p.rotator }, "Stop");
    });
    const svg = $(".compass", el);
    svg.addEventListener("pointerup", (e) => {
      const t = p.compassTarget;
      if (!connected) { say(p, "Turn: " + REFUSALS.reconnecting, "warning"); return; }
      if (!t || !t.rotator.online) return;
      const heading = MoasCompass.headingAt(svg, e.clientX, e.clientY, t.offset);
      if (heading != null) act(p, { cmd: "rotate", rotator: t.rotator.id, heading }, `Turn to ${Math.round(heading)}\u00b0`);
    });
    return p;
  }

  function send(p, obj, what) {
    if (choice.station == null || p.radio == null) return;
    const refusal = REFUSALS[currentScreen()];
    if (refusal) { say(p, `${what}: ${refusal}`, "warning"); return; }
    act(p, { ...obj, station: choice.station, radio: p.radio }, what);
  }
  function act(p, obj, what) {
    clearMessage(p);
    const asked = what || obj.cmd;
    request(obj).catch(e => { say(p, `${asked}: ${e.message}`, "warning"); });
  }

  function antenna(id) { return id == null || !snapshot ? null : snapshot.antennas.find(a => a.id === id) || null; }
  function antennaName(id) { const a = antenna(id); return a ? (a.long || a.short || `Antenna ${a.id}`) : "none"; }
  function radioView(p) {
    return snapshot ? snapshot.radios.find(r => r.station === choice.station && r.radio === p.radio) || null : null;
  }
  // the server said the radio has no relative list here (an entry without the field
  // says nothing: the step is sent and the server answers)
  // a moment the server gave in UTC, as this device's clock shows it: 09:14 (with the date when not today)
  function localTime(utc) {
    if (!utc) return "";
    const t = new Date(utc);
    if (Number.isNaN(t.getTime())) return "";
    const two = (n) => String(n).padStart(2, "0");
    const time = `${two(t.getHours())}:${two(t.getMinutes())}`;
    const now = new Date();
    return t.toDateString() === now.toDateString() ? time
      : `${t.getFullYear()}-${two(t.getMonth() + 1)}-${two(t.getDate())} ${time}`;
  }
  // an anonymous page (this computer, an open LAN) may; an operator by its role
  function mayRelease(r) {
    if (!operator) return true;
    if (operator.role === "admin") return true;
    if (operator.role !== "operate") return false;
    return operator.radios == null || operator.radios.some(([s, n]) => s === r.station && n === r.radio);
  }
  function noRelative(r) { return "relative" in r && !(r.relative && r.relative.length); }
  function khzText(khz) { return khz == null ? "no frequency" : `${khz.toFixed(1)} kHz`; }

  function whyText(r) {
    const lines = [];
    if (r.why && r.why.text) {
      lines.push(r.why.text.charAt(0).toUpperCase() + r.why.text.slice(1));
      for (const item of r.why.passed_over || []) lines.push(`${antennaName(item.antenna)}: ${item.reason}`);
    }
    // why the radio has no alternate antenna while another radio would switch it to one
    if (r.alt_why) lines.push(`No alternate antenna ${r.alt_why}`);
    return lines.join("\n");
  }

  function showRadio(p) {
    const r = radioView(p);
    const el = p.el;
    const freq = $(".freq", el), tx = $(".ant-tx", el), rx = $(".ant-rx", el), note = $(".note", el);
    if (!r || !showsSelection()) {
      freq.textContent = {
        "switches stopped": "Switches stopped: no antenna is connected",
        "reconnecting": "Not connected: the antennas in use are not known",
        "no configuration": "The server has no configuration open",
      }[screenState()] || "no radio";
      tx.textContent = rx.textContent = "";
      $(".transmitting", el).hidden = $(".inhibited", el).hidden = note.hidden = true;
      $(".release", el).hidden = true;
      if (r) $(".rel-list", el).textContent = (r.relative || []).map(id => antenna(id) ? antenna(id).short || antennaName(id) : id).join("  ");
      return;
    }
    freq.textContent = r.tx_khz != null && r.khz != null && r.tx_khz !== r.khz
      ? `${khzText(r.khz)} / TX ${khzText(r.tx_khz)}` : khzText(r.khz);
    tx.textContent = `TX ${antennaName(r.tx)}`;
    rx.textContent = `RX ${antennaName(r.rx)}` + (r.alt != null ? ` \u00b7 ALT ${antennaName(r.alt)}` : "");
    $(".transmitting", el).hidden = !r.transmitting;
    $(".inhibited", el).hidden = !r.inhibited;
    const since = localTime(r.held_since);
    const held = r.held_by ? `Held by ${r.held_by}${since ? " since " + since : ""}: the antennas do not follow the frequency` : "";
    note.textContent = [r.note || "", held].filter(Boolean).join(" \u00b7 ");
    note.hidden = !note.textContent;
    $(".release", el).hidden = !(r.held_by && mayRelease(r));
    const why = $(".why", el);
    why.textContent = whyText(r);
    $(".display", el).title = why.textContent;
    if (!why.textContent) why.hidden = true;
    const rel = (r.relative || []).map(id => (id === r.tx ? "\u25b8" : "") + (antenna(id) ? antenna(id).short || antennaName(id) : id));
    $(".rel-list", el).textContent = rel.join("  ");
    // without a relative list the steps look unavailable but answer a tap with why
    const none = noRelative(r);
    for (const b of [$(".prev", el), $(".next", el)]) {
      b.setAttribute("aria-disabled", String(none));
      b.title = none ? `no relative antenna list at ${khzText(r.khz)}` : "";
    }
  }

  // -- buttons -----------------------------------------------------------------------------------
  function wantedShape(p) {
    const width = $(".grid", p.el).clientWidth || p.el.clientWidth || 300;
    const columns = Math.max(1, Math.min(8, Math.floor(width / 110)));
    const rows = Math.max(1, Math.min(8, Math.floor((window.innerHeight - 300) / 70)));
    return [rows, columns];
  }

  function askLayout(p) {
    if (!connected || choice.station == null || p.radio == null) return;
    const [rows, columns] = wantedShape(p);
    const key = { station: choice.station, radio: p.radio, rows, columns };
    if (p.asked && JSON.stringify(p.asked) === JSON.stringify(key)) return;
    p.asked = key;
    request({ cmd: "layout", ...key }).then((layout) => {
      if (p.asked !== key) return;
      p.shape = [layout.rows, layout.columns];
      showLayout(p, layout);
    }, (e) => { say(p, "Layout: " + e.message, "warning"); });
  }

  function showLayout(p, layout) {
    p.layout = layout;
    const grid = $(".grid", p.el);
    let rows = layout.rows, columns = layout.columns;
    for (const b of layout.buttons) { rows = Math.max(rows, b.row + 1); columns = Math.max(columns, b.column + 1); }
    grid.style.gridTemplateColumns = `repeat(${columns}, minmax(0, 1fr))`;
    const keep = new Map([...grid.children].map(b => [b.dataset.cell, b]));
    for (const view of layout.buttons) {
      const cell = `${view.row},${view.column}`;
      let b = keep.get(cell);
      if (b) keep.delete(cell); else { b = makeButton(p); grid.append(b); }
      b.dataset.cell = cell;
      b.style.gridRow = String(view.row + 1);
      b.style.gridColumn = String(view.column + 1);
      showButton(b, view);
    }
    for (const gone of keep.values()) gone.remove();
    showCompass(p);
  }

  function showButton(b, view) {
    b.view = view;
    const hidden = !showsSelection();  // stopped, not connected: what each would be is not so now
    if (hidden && view.state !== "available") view = { ...view, state: "available" };
    b.dataset.state = view.state;
    b.dataset.type = view.type;
    b.dataset.id = String(view.id);
    const mark = view.state === "selected" ? "\u2714 " : view.type === "Function" ? "\u0192 " : "";
    b.textContent = mark + (view.label || `#${view.id}`);
    // an unavailable button keeps its look but is never disabled: a tap is answered with its reason
    b.setAttribute("aria-disabled", String(view.state === "unavailable"));
    b.setAttribute("aria-pressed", String(view.state === "selected"));
    const said = hidden ? (REFUSALS[currentScreen()] || view.state)
      : view.state === "unavailable" && view.reason ? `unavailable: ${view.reason}` : view.state;
    b.title = `${view.label} (${view.type === "Function" ? "function" : "antenna"} ${view.id}): ${said}`;
    b.setAttribute("aria-label", `${view.label}: ${said}`);
  }

  /* What Why? (a right-click) or a tap on an unavailable button answers: the same
     words as the desktop client (moas_gui/client/screen.py button_answer). */
  function buttonAnswer(p, view) {
    const refusal = REFUSALS[currentScreen()];
    if (refusal) return `${view.label}: ${refusal}`;
    const fn = view.type === "Function";
    if (view.state === "unavailable") return `${view.label}: ${view.reason || "not available now (the server did not say why)"}`;
    if (view.state === "selected") {
      if (fn) return `${view.label}: on; a click turns it off`;
      const r = radioView(p), why = r ? whyText(r).replace(/\n/g, "; ") : "";
      return `${view.label}: in use by this radio` + (why ? `. ${why}` : "");
    }
    return `${view.label}: available; a click ` + (fn ? "runs it" : "selects it");
  }

  /* Tap selects (additive antennas toggle: the server decides); a long press
     selects that antenna alone. */
  function makeButton(p) {
    const b = document.createElement("button");
    b.type = "button";
    let timer = null, long = false, down = false;
    const cancel = () => { clearTimeout(timer); timer = null; down = false; b.classList.remove("pressing"); };
    b.addEventListener("pointerdown", (e) => {
      if (e.button > 0) return;
      down = true; long = false; b.classList.add("pressing");
      timer = setTimeout(() => {
        long = true; timer = null;
        if (navigator.vibrate) navigator.vibrate(30);
        press(p, b.view, true);
      }, LONG_PRESS_MS);
    });
    b.addEventListener("pointerup", () => { if (down && !long) press(p, b.view, false); cancel(); });
    b.addEventListener("pointerleave", cancel);
    b.addEventListener("pointercancel", cancel);
    b.addEventListener("contextmenu", (e) => {  // a mouse's right-click asks Why?
      e.preventDefault();
      if (e.pointerType === "touch" || long || down) return;  // a finger's long press selects
      if (b.view) say(p, buttonAnswer(p, b.view), "info");
    });
    b.addEventListener("click", (e) => { if (e.detail === 0) press(p, b.view, false); });  // keyboard
    return b;
  }

  function press(p, view, exclusive) {
    if (!view) return;
    if (view.state === "unavailable" && showsSelection()) { say(p, buttonAnswer(p, view), "info"); return; }
    if (view.type === "Function") send(p, { cmd: "function", function: view.id }, `Function ${view.label}`);
    else send(p, { cmd: "select", antenna: view.id, target: p.target, exclusive }, `Select ${view.label}`);
  }

  // -- compass -----------------------------------------------------------------------------------
  function compassTargets(p) {
    const r = radioView(p);
    if (!r || !snapshot) return [];
    const inUse = [r.tx, r.rx].filter(i => i != null);
    const marked = showsSelection() ? inUse : [];
    const onButtons = p.layout ? p.layout.buttons.filter(b => b.type === "Antenna").map(b => b.id) : [];
    const seen = new Map();
    for (const id of new Set([...inUse, ...onButtons])) {
      const a = antenna(id);
      if (!a || a.rotator == null || seen.has(a.rotator)) continue;
      const rot = snapshot.rotators.find(x => x.id === a.rotator);
      if (!rot) continue;
      if (rot.electrical) {
        const dirs = snapshot.antennas.filter(x => x.rotator === rot.id)
          .map(x => ({ heading: x.offset || 0, active: marked.includes(x.id) }));
        seen.set(rot.id, { rotator: rot, offset: 0, directions: dirs, label: rot.short || rot.long });
      } else {
        seen.set(rot.id, { rotator: rot, offset: a.offset || 0, directions: [], label: a.short || rot.short });
      }
    }
    return [...seen.values()];
  }

  function showCompass(p) {
    const box = $(".compass-box", p.el);
    const targets = compassTargets(p);
    box.hidden = targets.length === 0;
    if (!targets.length) { p.compassTarget = null; return; }
    // the chooser follows the transmit antenna's rotator; a rotator picked by hand
    // stays until another antenna is in use
    const r = radioView(p), txAntenna = r ? antenna(r.tx) : null;
    const prefer = txAntenna && txAntenna.rotator != null ? txAntenna.rotator : null;
    if (prefer !== p.prefer) { p.prefer = prefer; if (prefer != null) p.picked = false; }
    if (!p.picked && prefer != null && targets.some(t => t.rotator.id === prefer)) p.rotator = prefer;
    if (!targets.some(t => t.rotator.id === p.rotator)) p.rotator = targets[0].rotator.id;
    const t = targets.find(x => x.rotator.id === p.rotator);
    p.compassTarget = t;
    const chooser = $(".rotator", p.el);
    chooser.replaceChildren(...targets.map(x => new Option(x.label || `Rotator ${x.rotator.id}`, String(x.rotator.id))));
    chooser.value = String(p.rotator);
    chooser.hidden = targets.length < 2;
    const svg = $(".compass", p.el);
    // not connected: the last heading heard is not the heading now, so none is drawn
    MoasCompass.draw(svg, connected ? t
      : { ...t, rotator: { ...t.rotator, heading: null, target: null, moving: false } });
    svg.classList.toggle("offline", !t.rotator.online || !connected);
    const rot = t.rotator;
    // the desktop client's format: "75\u00b0", "200\u00b0 \u2192 75\u00b0", "heading unknown"
    let text = rot.online ? (rot.heading == null ? "heading unknown" : `${degrees(rot.heading + t.offset)}\u00b0`) : "offline";
    if (rot.online && rot.moving && rot.target != null) text += ` \u2192 ${degrees(rot.target + t.offset)}\u00b0`;
    if (!connected) text = "not connected";  // the last heading heard is not the heading now
    $(".heading", p.el).textContent = text;
    $(".stop", p.el).disabled = connected && !rot.online;
  }
  function degrees(h) { return String(Math.round(MoasCompass.norm(h)) % 360); }

  let resizeTimer = null;
  window.addEventListener("resize", () => {
    clearTimeout(resizeTimer);
    resizeTimer = setTimeout(() => { for (const p of panels) askLayout(p); }, 200);
  });

  // A page the browser keeps for its Back button must not stay connected (and
  // counted) while hidden; it connects again when shown.
  let parked = false;
  window.addEventListener("pagehide", () => {
    parked = true;
    const socket = ws;
    ws = null;
    connected = false;
    if (socket) socket.close(1000, "page hidden");
  });
  window.addEventListener("pageshow", (e) => {
    if (e.persisted && parked) { parked = false; showLink(false, "connecting\u2026"); connect(); }
  });

  showLink(false, "connecting\u2026");
  connect();
})();
