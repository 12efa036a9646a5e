// The reflectance plot: R, G, B against the angle theta (0 to 90 degrees) in
// SVG, with draggable, focusable control points on the edited target.

const SVG = "http://www.w3.org/2000/svg";
const M = { left: 48, right: 14, top: 12, bottom: 36 };
// The drawing's size in SVG units follows its width on screen (320 to 640
// CSS px at one unit a pixel, scaled up beyond): axis text of 11 units stays
// 11 px or more on a phone, and a handle's hit area is at least 24 px.
const W_MIN = 320, W_MAX = 640;
// Arrow-key presses on a point within this long of each other are one edit (one undo step).
export const KEY_BURST_MS = 700;
const sizeFor = (px) => {
  const width = Math.round(Math.min(W_MAX, Math.max(W_MIN, px || W_MAX)));
  return { width, height: Math.round(Math.max(260, 0.625 * width)) };
};
const MOVE_EVENT = typeof window !== "undefined" && "onpointerrawupdate" in window ? "pointerrawupdate" : "pointermove";
export const HANDLE_HIT_PX = 24; // a handle's diameter on screen at least (touch)

function el(name, attributes = {}, parent = null) {
  const node = document.createElementNS(SVG, name);
  for (const [key, value] of Object.entries(attributes)) node.setAttribute(key, value);
  if (parent) parent.appendChild(node);
  return node;
}

export class ReflectancePlot {
  /**
   * @param {HTMLElement} container
   * @param {object} hooks  onDrag(channel, handleIndex, value, pointer, event) -> whether the point moved
   *   (pointer: true while a pointer drags it, with its move event; false for a key press), onDragEnd() (the drag, or
   *   a burst of key presses, ended), onSelect(channel, handleIndex) (a point took the focus)
   */
  constructor(container, hooks) {
    this.hooks = hooks;
    this.svg = el("svg", { role: "group", "aria-label": "Reflectance curves" });
    container.appendChild(this.svg);
    this.#resize(container.clientWidth);
    // A new width redraws at its own size (never during a drag: the point stays under the pointer).
    new ResizeObserver(() => {
      if (!this.dragging && this.#resize(container.clientWidth) && this.data) this.draw(this.data);
    }).observe(container);
    this.yMin = 0;
    this.yMax = 1;
    this.layers = {};
    for (const name of ["grid", "axis", "critical", "lazanyi", "reference", "target", "compare", "model", "handles"]) {
      this.layers[name] = el("g", { class: name }, this.svg);
    }
    this.dragging = null;
    this.keyBurst = null; // the timer that ends a burst of key presses (one undo step)
    // A held point follows the pointer's raw updates where the browser has them (a secure context in
    // Chromium): each as it comes in, not held back to the next animation frame as pointermove is.
    this.svg.addEventListener(MOVE_EVENT, (event) => this.#move(event));
    this.svg.addEventListener("pointerup", () => this.#release());
    this.svg.addEventListener("pointercancel", () => this.#release());
  }

  // Whether the size changed.
  #resize(px) {
    const { width, height } = sizeFor(px);
    if (width === this.W && height === this.H) return false;
    this.W = width;
    this.H = height;
    this.svg.setAttribute("viewBox", `0 0 ${width} ${height}`);
    this.signature = null; // handles rebuilt at their new size
    return true;
  }

  // A handle's radius in SVG units: 12 px wide on screen for a mouse, HANDLE_HIT_PX
  // for a finger (a coarse pointer, or a window narrower than 560 px: a phone).
  #radius() {
    const scale = this.svg.getBoundingClientRect().width / this.W || 1;
    const touch = window.matchMedia("(max-width: 560px), (pointer: coarse)").matches;
    return Math.max(5, (touch ? HANDLE_HIT_PX : 12) / 2 / scale);
  }

  x(theta) { return M.left + (theta / 90) * (this.W - M.left - M.right); }
  y(value) { return this.H - M.bottom - ((value - this.yMin) / (this.yMax - this.yMin)) * (this.H - M.top - M.bottom); }
  value(py) { return this.yMin + ((this.H - M.bottom - py) / (this.H - M.top - M.bottom)) * (this.yMax - this.yMin); }

  #axes() {
    const { grid, axis } = this.layers;
    const { W, H } = this;
    // Drawn again only for a new size or scale (not on every move of a drag).
    const signature = `${W} ${H} ${this.yMin} ${this.yMax}`;
    if (signature === this.axesSignature) return;
    this.axesSignature = signature;
    grid.replaceChildren();
    axis.replaceChildren();
    for (let t = 0; t <= 90; t += 15) {
      el("line", { x1: this.x(t), x2: this.x(t), y1: M.top, y2: H - M.bottom }, grid);
      el("text", { x: this.x(t), y: H - M.bottom + 16, "text-anchor": "middle" }, axis).textContent = `${t}°`;
    }
    const step = this.yMax - this.yMin > 0.5 ? 0.1 : 0.05;
    for (let v = Math.ceil(this.yMin / step) * step; v <= this.yMax + 1e-9; v += step) {
      el("line", { x1: M.left, x2: W - M.right, y1: this.y(v), y2: this.y(v) }, grid);
      el("text", { x: M.left - 6, y: this.y(v) + 4, "text-anchor": "end" }, axis).textContent = v.toFixed(2);
    }
    el("text", { x: (M.left + W - M.right) / 2, y: H - 4, "text-anchor": "middle" }, axis).textContent = "angle θ inside the coating";
  }

  // A layer's three curves: its paths kept, their `d` set (none when `rgb` is null).
  #path(layer, theta, rgb, className) {
    if (!rgb) {
      layer.replaceChildren();
      return;
    }
    if (layer.childElementCount !== 3) {
      layer.replaceChildren();
      for (let c = 0; c < 3; c++) el("path", { class: `${className} c${c}`, "data-channel": c }, layer);
    }
    for (let c = 0; c < 3; c++) {
      const d = theta.map((t, i) => `${i ? "L" : "M"}${this.x(t).toFixed(1)},${this.y(rgb[i][c]).toFixed(1)}`).join("");
      if (layer.children[c].getAttribute("d") !== d) layer.children[c].setAttribute("d", d);
    }
  }

  /**
   * Draw everything. `data`: theta (n), reference, target, model, lazanyi,
   * compare (compare mode's other fit; each n x 3 or null), handles: angles of the control points, channel:
   * 0, 1, 2 or "all" (which handles take the pointer).
   */
  draw(data) {
    this.data = data;
    const all = [data.reference, data.target, data.model, data.lazanyi, data.compare].filter(Boolean).flat(2);
    // The grazing end is 1 for every curve; the interesting part is the dip.
    // The scale stays put during a drag so that the point stays under the pointer.
    if (!this.dragging) this.yMin = Math.max(0, Math.floor((Math.min(...all) - 0.05) * 10) / 10);
    this.yMax = 1.0;
    this.#axes();
    const critical = this.layers.critical;
    critical.replaceChildren();
    if (data.criticalDeg) {
      // The largest angle inside a flat coat seen from air: asin(1 / eta_i).
      const x = this.x(data.criticalDeg);
      el("line", { x1: x, x2: x, y1: M.top, y2: this.H - M.bottom }, critical);
      el("text", { x: x + 4, y: M.top + 12 }, critical).textContent = `max from air ${data.criticalDeg.toFixed(1)}°`;
    }
    for (const name of ["lazanyi", "reference", "target", "compare", "model"]) {
      this.#path(this.layers[name], data.theta, data[name], name);
    }
    this.#handles();
  }

  #handles() {
    const layer = this.layers.handles;
    const { theta, target, handles, channel } = this.data;
    const signature = target ? `${handles.join(",")}|${channel}` : "";
    if (signature !== this.signature) {
      // Rebuilt only when the set of handles changes, never during a drag
      // (a new element would lose the pointer capture and the focus).
      this.signature = signature;
      layer.replaceChildren();
      this.nodes = new Map();
      if (target) this.#buildHandles(layer, handles, channel);
    }
    if (!target) return;
    for (const [key, circle] of this.nodes) {
      const [c, h] = key.split(":").map(Number);
      const value = target[theta.indexOf(handles[h])][c];
      circle.setAttribute("cy", this.y(value));
      circle.setAttribute("aria-valuenow", value.toFixed(3));
      circle.setAttribute("aria-valuetext", `${value.toFixed(3)} at ${handles[h]} degrees`);
    }
  }

  #buildHandles(layer, handles, channel) {
    const names = ["red", "green", "blue"];
    const radius = this.#radius().toFixed(1);
    handles.forEach((angle, h) => {
      for (let c = 0; c < 3; c++) {
        const active = channel === "all" || Number(channel) === c;
        const circle = el("circle", {
          cx: this.x(angle), r: radius, class: `handle c${c}${active ? "" : " inactive"}`,
          tabindex: active ? 0 : -1, role: "slider",
          "aria-label": `${names[c]} reflectance at ${angle} degrees`,
          "aria-valuemin": 0, "aria-valuemax": 1,
          "data-channel": c, "data-handle": h, "data-angle": angle,
        }, layer);
        this.nodes.set(`${c}:${h}`, circle);
        if (!active) continue;
        circle.addEventListener("pointerdown", (event) => {
          event.preventDefault();
          circle.setPointerCapture(event.pointerId);
          circle.focus();
          this.dragging = { channel: c, handle: h, moved: false };
        });
        circle.addEventListener("keydown", (event) => this.#key(event, c, h));
        circle.addEventListener("focus", () => this.hooks.onSelect && this.hooks.onSelect(c, h));
        circle.addEventListener("blur", () => this.endKeyBurst());
      }
    });
  }

  #key(event, c, h) {
    const { theta, target, handles } = this.data;
    const current = target[theta.indexOf(handles[h])][c];
    const steps = { ArrowUp: 0.01, ArrowDown: -0.01, PageUp: 0.05, PageDown: -0.05 };
    if (!(event.key in steps)) return;
    event.preventDefault();
    const step = steps[event.key] * (event.shiftKey ? 5 : 1);
    if (!this.hooks.onDrag(c, h, Math.min(1, Math.max(0, current + step)), false)) return;
    // Presses in quick succession are one edit: it ends KEY_BURST_MS after the last (or when the point loses the focus).
    clearTimeout(this.keyBurst);
    this.keyBurst = setTimeout(() => this.endKeyBurst(), KEY_BURST_MS);
  }

  /** End a burst of key presses now (one undo step for it); nothing when none is under way. */
  endKeyBurst() {
    if (this.keyBurst === null) return;
    clearTimeout(this.keyBurst);
    this.keyBurst = null;
    this.hooks.onDragEnd();
  }

  #move(event) {
    if (!this.dragging) return;
    const point = this.svg.createSVGPoint();
    point.x = event.clientX;
    point.y = event.clientY;
    const local = point.matrixTransform(this.svg.getScreenCTM().inverse());
    const value = Math.min(1, Math.max(0, this.value(local.y)));
    if (this.hooks.onDrag(this.dragging.channel, this.dragging.handle, value, true, event)) this.dragging.moved = true;
  }

  #release() {
    if (!this.dragging) return;
    const moved = this.dragging.moved;
    this.dragging = null;
    if (moved) this.hooks.onDragEnd();
  }
}
