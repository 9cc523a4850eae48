// rtcli preview: the page (docs/preview.md). It draws the tiles the server sends as they come
// (rtcli/preview/messages.py), switches views, and explains the pixel clicked.
"use strict";
(() => {
  const $ = (id) => document.getElementById(id);
  const token = new URLSearchParams(location.search).get("token") || "";
  const canvas = $("image"), ctx = canvas.getContext("2d");
  const overlay = $("overlay"), octx = overlay.getContext("2d");
  const scratch = document.createElement("canvas"), sctx = scratch.getContext("2d");
  // What the page knows; window.rtcliPreview for tools and tests: marks records when whole
  // pictures were drawn ({render, block, at: ms since the page began, wall: Date.now()}).
  const state = {
    render: 0, width: 0, height: 0, blocks: [], ids: null, objects: new Map(), view: "image",
    clicked: null, frames: 1, against: null, compared: false, marks: [], ws: null,
  };
  window.rtcliPreview = state;

  const url = (path, params = {}) => {
    const u = new URL(path, location.href);
    u.search = "";
    if (token) u.searchParams.set("token", token);
    for (const [k, v] of Object.entries(params)) u.searchParams.set(k, v);
    return u.toString();
  };

  // --- numbers as `rtcli explain` prints them (Python's %.6g) ---
  function num(x) {
    if (typeof x !== "number") return String(x);
    if (x === 0) return "0";
    if (!isFinite(x)) return x > 0 ? "inf" : x < 0 ? "-inf" : "nan";
    const [mantissa, e] = x.toExponential(5).split("e");
    const exp = Number(e);
    const trim = (s) => (s.includes(".") ? s.replace(/0+$/, "").replace(/\.$/, "") : s);
    if (exp < -4 || exp >= 6) return `${trim(mantissa)}e${exp < 0 ? "-" : "+"}${String(Math.abs(exp)).padStart(2, "0")}`;
    return trim(x.toFixed(5 - exp));
  }
  const vec = (v) => "(" + v.map(num).join(", ") + ")";

  function el(tag, attrs = {}, ...children) {
    const e = document.createElement(tag);
    for (const [k, v] of Object.entries(attrs)) {
      if (k === "class") e.className = v; else if (v !== false && v !== null) e.setAttribute(k, v === true ? "" : v);
    }
    e.append(...children.filter((c) => c !== null && c !== undefined));
    return e;
  }

  // --- the websocket ---
  function connect() {
    const ws = new WebSocket(url("ws").replace(/^http/, "ws"));
    ws.binaryType = "arraybuffer";
    ws.onmessage = (e) => (typeof e.data === "string" ? onJson(JSON.parse(e.data)) : onBinary(e.data));
    ws.onclose = () => {
      setState("disconnected");
      $("status").textContent = "disconnected: is rtcli preview still running? trying again";
      setTimeout(connect, 2000);
    };
    state.ws = ws;
  }

  function onBinary(buffer) {
    const v = new DataView(buffer);
    const kind = v.getUint8(0), block = v.getUint8(1), render = v.getUint32(4, true);
    const x = v.getUint16(8, true), y = v.getUint16(10, true);
    const cols = v.getUint16(12, true), rows = v.getUint16(14, true);
    if (kind === 1) {
      drawTile(new Uint8Array(buffer, 16), block, x, y, cols, rows);
      if (x === 0 && y === 0 && cols * block >= state.width && rows * block >= state.height) {
        mark(render, block);                            // a whole picture in one message
      }
    } else if (kind === 2) {
      state.ids = { data: new Uint16Array(buffer, 16, cols * rows), width: cols, height: rows, render };
      if (state.clicked) outline(state.clicked.x, state.clicked.y);
    }
  }

  function drawTile(rgb, block, x, y, cols, rows) {
    const rgba = new Uint8ClampedArray(cols * rows * 4);
    for (let i = 0, j = 0; i < rgba.length; i += 4, j += 3) {
      rgba[i] = rgb[j]; rgba[i + 1] = rgb[j + 1]; rgba[i + 2] = rgb[j + 2]; rgba[i + 3] = 255;
    }
    const picture = new ImageData(rgba, cols, rows);
    if (block === 1) {
      ctx.putImageData(picture, x, y);
      return;
    }
    scratch.width = cols; scratch.height = rows;
    sctx.putImageData(picture, 0, 0);
    ctx.imageSmoothingEnabled = false;                  // each value fills its block x block square
    ctx.drawImage(scratch, x, y, cols * block, rows * block);
  }

  function mark(render, block) {
    const last = state.marks[state.marks.length - 1];
    if (last && last.render === render && last.block === block) return;     // the same picture, told twice
    state.marks.push({ render, block, at: performance.now(), wall: Date.now() });
    document.body.dataset.pictures = String(state.marks.length);
  }

  function setState(name) { document.body.dataset.state = name; }

  function onJson(m) {
    const on = { scene: onScene, progress: onProgress, done: onDone, error: onError, compare: onCompare,
      note: (n) => { $("status").textContent = n.line; } }[m.type];
    if (on) on(m);
  }

  function onScene(m) {
    state.render = m.render;
    document.body.dataset.render = String(m.render);
    setState("rendering");
    $("title").textContent = m.title;
    $("status").textContent = "rendering";
    document.title = `${m.title} · rtcli preview`;
    if (m.width !== state.width || m.height !== state.height) resize(m.width, m.height);
    state.blocks = [16, 8, 4, 2, 1].filter((b) => b === 1 || b < Math.max(m.width, m.height));
    state.objects = new Map(m.objects.map((o) => [o.id, o]));
    state.frames = m.frames;
    $("frames").hidden = m.frames < 2;
    $("frame").max = String(m.frames);
    $("frame").value = String(m.frame);
    $("frame-label").textContent = `${m.frame} of ${m.frames}`;
    const warnings = $("warnings");
    warnings.replaceChildren(...m.warnings.map((w) => el("li", {}, w)));
    warnings.hidden = m.warnings.length === 0;
    state.against = m.against;
    $("against").hidden = !m.against;
    if (m.against) {
      $("golden-name").textContent = `golden ${m.against.name}:`;
      const flip = document.querySelector('[data-view="flip"]');
      flip.disabled = !m.against.flip;
      flip.title = m.against.flip ? "" : "FLIP needs flip-evaluator: pip install -e '.[flip]' in the rtcli folder";
    }
    state.compared = false;
  }

  function resize(w, h) {
    state.width = w; state.height = h;
    for (const c of [canvas, overlay]) { c.width = w; c.height = h; }
    // small pictures are shown bigger, by a whole factor, so that blocks stay square
    const zoom = Math.max(1, Math.floor(Math.min(720, window.innerWidth - 460) / w));
    $("stage").style.width = `${w * zoom}px`;
    state.ids = null;
  }

  function onProgress(m) {
    const share = m.pixels ? m.traced / m.pixels : 0;
    $("bar").style.width = `${(100 * share).toFixed(1)}%`;
    $("progress").setAttribute("aria-valuenow", String(Math.round(100 * share)));
    const k = state.blocks.indexOf(m.block) + 1;
    const eta = m.eta === null ? "" : ` · about ${m.eta < 10 ? m.eta.toFixed(1) : Math.round(m.eta)} s left`;
    $("status").textContent = `pass ${k} of ${state.blocks.length}: one ray per ${m.block}×${m.block} ` +
      `block · ${Math.floor(100 * share)}%${eta}`;
    document.body.dataset.block = String(m.block);
    if (m.last) mark(m.render, m.block);
  }

  function onDone(m) {
    setState("done");
    $("bar").style.width = "100%";
    $("status").textContent = `done in ${m.seconds.toFixed(2)} s`;
    $("stats").textContent = m.stats;
    if (state.view !== "image" && state.view !== "slider") show(state.view);
  }

  function onError(m) {
    const box = $("error");
    box.hidden = !m.line;
    box.textContent = m.line || "";
    document.body.dataset.error = m.line ? "1" : "";
  }

  function onCompare(m) {
    state.compared = true;
    $("against").dataset.ok = m.ok ? "1" : "0";
    if (["slider", "diff", "flip"].includes(state.view)) show(state.view);
    else $("summary").textContent = `golden: ${m.summary}`;
    state.comparison = m;
  }

  // --- views ---
  function show(view) {
    state.view = view;
    for (const b of document.querySelectorAll("[data-view]")) b.setAttribute("aria-pressed", String(b.dataset.view === view));
    const picture = $("picture"), golden = $("golden"), split = $("split"), summary = $("summary");
    picture.hidden = golden.hidden = split.hidden = $("seam").hidden = true;
    summary.textContent = "";
    if (view === "image") return;
    if (view === "slider") {
      golden.src = url("against/golden.png");
      golden.hidden = split.hidden = $("seam").hidden = false;
      clip();
      summary.textContent = state.comparison ? `golden: ${state.comparison.summary}` : "golden: the render is not done";
      return;
    }
    if (view === "diff" || view === "flip") {
      if (!state.comparison || !state.comparison[view]) {
        summary.textContent = state.comparison ? `golden: ${state.comparison.summary}` : "golden: the render is not done";
        return;
      }
      picture.src = url(`against/${view}.png`, { render: state.render });
      picture.hidden = false;
      summary.textContent = `golden: ${state.comparison.summary}`;
      return;
    }
    summary.textContent = `computing the ${view} view`;
    const render = state.render;
    picture.src = url(`view/${view}.png`, { render });
    picture.hidden = false;
    fetch(url(`view/${view}.json`, { render })).then(answer).then((j) => {
      if (state.view === view) summary.textContent = JSON.parse(j).summary;
    }).catch((e) => { summary.textContent = String(e.message || e); });
  }

  function clip() {                         // the slider: the render on the left, the golden image on the right
    $("golden").style.clipPath = `inset(0 0 0 ${$("split").value}%)`;
    $("seam").style.marginLeft = `calc(${$("split").value}% - 1px)`;
  }

  async function answer(response) {
    const text = await response.text();
    if (!response.ok) throw new Error(text.trim());
    return text;
  }

  // --- the pixel under the cursor, the pixel clicked ---
  function pixelAt(event) {
    const r = overlay.getBoundingClientRect();
    const x = Math.floor((event.clientX - r.left) * state.width / r.width);
    const y = Math.floor((event.clientY - r.top) * state.height / r.height);
    return x >= 0 && y >= 0 && x < state.width && y < state.height ? { x, y } : null;
  }

  function objectAt(x, y) {
    const ids = state.ids;
    if (!ids || ids.width !== state.width || ids.height !== state.height) return undefined;
    return ids.data[y * ids.width + x];
  }

  function describe(id) {
    if (id === undefined) return "";
    if (id === 0) return "the background";
    const o = state.objects.get(id);
    return o ? `#${id} ${o.name || "(unnamed)"} · ${o.shape} · material ${o.material}` : `#${id}`;
  }

  overlay.addEventListener("mousemove", (event) => {
    const p = pixelAt(event);
    if (!p) return;
    const [r, g, b] = ctx.getImageData(p.x, p.y, 1, 1).data;
    $("hover").textContent = `(${p.x}, ${p.y}) ${describe(objectAt(p.x, p.y))} · 8-bit (${r}, ${g}, ${b})`;
  });
  overlay.addEventListener("mouseleave", () => { $("hover").textContent = "\u00a0"; });
  overlay.addEventListener("click", (event) => {
    const p = pixelAt(event);
    if (p) explain(p.x, p.y);
  });

  function outline(x, y) {
    // the clicked object's edge: its pixels with a 4-neighbour of another id (or the image's border)
    octx.clearRect(0, 0, overlay.width, overlay.height);
    const id = objectAt(x, y), ids = state.ids;
    if (id) {
      const w = ids.width, h = ids.height, d = ids.data, edge = octx.createImageData(w, h);
      for (let j = 0; j < h; j++) {
        for (let i = 0; i < w; i++) {
          const k = j * w + i;
          if (d[k] !== id) continue;
          if (i === 0 || j === 0 || i === w - 1 || j === h - 1 || d[k - 1] !== id || d[k + 1] !== id ||
              d[k - w] !== id || d[k + w] !== id) {
            edge.data.set([0, 229, 255, 255], 4 * k);
          }
        }
      }
      octx.putImageData(edge, 0, 0);
    }
    octx.fillStyle = "#ff3df5";                          // the pixel itself, with a small cross
    octx.fillRect(x - 4, y, 3, 1); octx.fillRect(x + 2, y, 3, 1);
    octx.fillRect(x, y - 4, 1, 3); octx.fillRect(x, y + 2, 1, 3);
    document.body.dataset.outlined = String(id || 0);
  }

  async function explain(x, y) {
    state.clicked = { x, y };
    outline(x, y);
    $("explain-head").textContent = `pixel (${x}, ${y}): tracing`;
    try {
      const [json, text] = await Promise.all([fetch(url("explain.json", { x, y })).then(answer),
        fetch(url("explain.txt", { x, y })).then(answer)]);
      if (state.clicked.x !== x || state.clicked.y !== y) return;
      showExplanation(JSON.parse(json), 0);
      $("text").textContent = text;
      $("as-text").hidden = false;
    } catch (e) {
      $("explain-head").textContent = String(e.message || e);
      $("tree").replaceChildren();
    }
  }

  // --- the ray tree: every number of `rtcli explain --json`, each tagged with its path there ---
  function val(path, v, shown) {
    const text = shown !== undefined ? shown : Array.isArray(v) ? vec(v) : typeof v === "number" ? num(v) : String(v);
    return el("span", { class: "n", "data-path": path, "data-value": JSON.stringify(v) }, text);
  }

  function row(...parts) {
    return el("div", { class: "row" }, ...parts.map((p) => (typeof p === "string" ? el("span", { class: "label" }, p) : p)));
  }

  function showExplanation(e, k) {
    const head = $("explain-head");
    head.replaceChildren("pixel ", val("pixel", e.pixel), " of ", val("image", e.image), " = ",
      val("value", e.value), " → 8-bit ", val("byte", e.byte), e.gamma ? " (sRGB)" : "",
      el("span", { class: "note" }, e.samples_per_pixel > 1 ? " the mean of " : " ",
        val("samples_per_pixel", e.samples_per_pixel), e.samples_per_pixel > 1 ? " samples" : " sample"));
    const samples = $("samples");
    samples.hidden = e.samples.length < 2;
    samples.replaceChildren(...e.samples.map((s, i) => {
      const b = el("button", { type: "button", "aria-pressed": String(i === k) }, `sample ${s.sample}`);
      b.addEventListener("click", () => showExplanation(e, i));
      return b;
    }));
    const s = e.samples[k], p = `samples.${k}`;
    $("tree").replaceChildren(row("sample ", val(`${p}.sample`, s.sample), " through ", val(`${p}.position`, s.position)),
      rayNode(s.ray, `${p}.ray`, true));
  }

  function rayNode(node, p, open) {
    const h = node.hit;
    const title = node.more ? [`${node.kind} ray and ${node.more - 1} below it, past the node budget: adds `, vec(node.contribution)]
      : h ? [`${node.kind} ray: hits #${h.object} ${h.name || "(unnamed)"} (${h.shape}) = `, vec(node.total)]
      : [`${node.kind} ray: misses, the background `, vec(node.value)];
    const d = el("details", { class: h || node.more ? "ray" : "ray miss", open }, el("summary", {}, ...title));
    d.append(row(val(`${p}.kind`, node.kind), " ray, depth ", val(`${p}.depth`, node.depth), ": from ",
      val(`${p}.origin`, node.origin), " along ", val(`${p}.direction`, node.direction),
      node.more ? null : el("span", { class: "note" }, "  (none of its rays summarised: "),
      node.more ? null : val(`${p}.more`, node.more), node.more ? null : el("span", { class: "note" }, ")")));
    if (node.weight) d.append(row("its weight in its parent's color: ", val(`${p}.weight`, node.weight)));
    if (node.more) {
      d.append(row(el("span", { class: "note" }, "… "), val(`${p}.more`, node.more),
        el("span", { class: "note" }, " more rays (this one and those below it, past the node budget: --max-nodes), total contribution "),
        val(`${p}.contribution`, node.contribution), el("span", { class: "label" }, "  (its color "), val(`${p}.value`, node.value),
        el("span", { class: "label" }, ")")));
      return d;
    }
    node.bailouts.forEach((cut, i) => {
      const q = `${p}.bailouts.${i}`;
      d.append(row(el("span", { class: "note" }, `${cut.kind} ray not traced: its weight `), val(`${q}.weight`, cut.weight),
        el("span", { class: "note" }, ", its path weight "), val(`${q}.path`, cut.path),
        el("span", { class: "note" }, " is below adc_bailout "), val(`${q}.adc_bailout`, cut.adc_bailout)));
    });
    if (!h) {
      d.append(row("misses every object: the background ", val(`${p}.value`, node.value)));
      return d;
    }
    d.append(...hitRows(h, `${p}.hit`));
    d.append(row("emission ", val(`${p}.emission`, node.emission)),
      row("ka Ia T ", val(`${p}.ambient_term`, node.ambient_term)),
      row("emission + ka Ia T ", val(`${p}.ambient`, node.ambient)));
    node.lights.forEach((light, i) => d.append(lightBlock(light, `${p}.lights.${i}`)));
    d.append(row(el("span", { class: "sum" }, "local "), val(`${p}.local`, node.local)));
    if (node.glass) d.append(glassRow(node.glass, `${p}.glass`));
    if (node.stopped) d.append(row(el("span", { class: "note" }, `max_depth ${node.depth} reached: no reflected or refracted ray`)));
    node.children.forEach((child, i) => d.append(rayNode(child, `${p}.children.${i}`, true)));
    d.append(row(el("span", { class: "sum" }, "= "), val(`${p}.total`, node.total),
      el("span", { class: "label" }, "  (the engine returned "), val(`${p}.value`, node.value), el("span", { class: "label" }, ")")));
    return d;
  }

  function hitRows(h, p) {
    const c = h.coefficients, q = `${p}.coefficients`;
    const coefficient = (name) => [` ${name} `, val(`${q}.${name}`, c[name])];
    return [
      row("hits #", val(`${p}.object`, h.object), " ", val(`${p}.name`, h.name || "(unnamed)"), " (",
        val(`${p}.shape`, h.shape), ") at t = ", val(`${p}.t`, h.t), ", point ", val(`${p}.point`, h.point), ", ",
        val(`${p}.entering`, h.entering, h.entering ? "entering" : "leaving (from inside)")),
      row("normal N ", val(`${p}.normal`, h.normal), ", geometric ", val(`${p}.geometric`, h.geometric)),
      row("material ", val(`${p}.material_name`, h.material_name), " (#", val(`${p}.material`, h.material), "):",
        ...["ka", "kd", "ks", "n", "emission", "kr", "kt", "ior", "fresnel", "shadow"].flatMap(coefficient),
        ...(c.texture ? coefficient("texture") : [])),
      row("texture T ", val(`${p}.texture`, h.texture)),
    ];
  }

  function lightBlock(light, p) {
    const d = el("details", { class: "light" },
      el("summary", {}, `light ${light.index} (${light.kind}): diffuse + specular `,
        vec(light.samples.reduce((s, x) => s.map((v, i) => v + x.diffuse[i] + x.specular[i]), [0, 0, 0]))));
    d.append(row("light ", val(`${p}.index`, light.index), " ", val(`${p}.kind`, light.kind), " at ",
      val(`${p}.position`, light.position), ", I ", val(`${p}.color`, light.color)));
    light.samples.forEach((s, i) => {
      const rows = sampleRows(s, `${p}.samples.${i}`);
      if (light.samples.length === 1) d.append(...rows);
      else d.append(el("details", { class: "sample" }, el("summary", {}, `sample ${s.cell}: ${s.feeler ? s.feeler.state : "faces away"}`), ...rows));
    });
    return d;
  }

  function sampleRows(s, p) {
    const out = [row("cell ", val(`${p}.cell`, s.cell), ", point ", val(`${p}.point`, s.point), ", L ", val(`${p}.L`, s.L)),
      row("N.L ", val(`${p}.NL`, s.NL), ", r ", val(`${p}.r`, s.r), ", attenuation ", val(`${p}.attenuation`, s.attenuation),
        ", spot ", val(`${p}.spot`, s.spot), ", w ", val(`${p}.weight`, s.weight))];
    if (!s.feeler) {
      out.push(row(el("span", { class: "note" }, "N.L <= 0: the surface faces away from it; no feeler")));
    } else {
      const f = s.feeler, q = `${p}.feeler`;
      const blocker = f.blocker ? [" by #", val(`${q}.blocker`, f.blocker), " ", val(`${q}.blocker_name`, f.blocker_name || "(unnamed)"),
        " at t = ", val(`${q}.blocker_t`, f.blocker_t)] : [];
      out.push(row("shadow feeler from ", val(`${q}.start`, f.start), ": ",
        el("span", { class: f.state === "clear" ? "" : "blocked" }, val(`${q}.state`, f.state)), ...blocker,
        ", lets through ", val(`${q}.through`, f.through)));
    }
    out.push(row("diffuse  w (N.L) I kd T ", val(`${p}.diffuse`, s.diffuse)));
    out.push(row("specular w (cos)^n I ks ", val(`${p}.specular`, s.specular),
      ...(s.cos !== null ? [", cos ", val(`${p}.cos`, s.cos)] : [])));
    return out;
  }

  function glassRow(g, p) {
    const refraction = g.tir ? [el("span", { class: "blocked" }, " total internal reflection: no refracted ray")]
      : [", refraction θt ", val(`${p}.theta_t`, g.theta_t), " deg"];
    return row("glass: n1 ", val(`${p}.n1`, g.n1), " → n2 ", val(`${p}.n2`, g.n2), ", cos θi ", val(`${p}.cos_i`, g.cos_i),
      ", incidence θi ", val(`${p}.theta_i`, g.theta_i), " deg", ...refraction, ", Fresnel R ", val(`${p}.R`, g.R),
      el("span", { class: "note" }, g.fresnel ? " (the weights: kr R and kt (1 - R))" : " (the weights: kr and kt as given; fresnel: false)"));
  }

  // --- the controls ---
  for (const b of document.querySelectorAll("[data-view]")) b.addEventListener("click", () => show(b.dataset.view));
  $("split").addEventListener("input", clip);
  $("frame").addEventListener("input", () => { $("frame-label").textContent = `${$("frame").value} of ${state.frames}`; });
  $("frame").addEventListener("change", () => {
    if (state.ws && state.ws.readyState === WebSocket.OPEN) state.ws.send(JSON.stringify({ frame: Number($("frame").value) }));
  });
  connect();
})();
