
window.__errors = [];
window.addEventListener("error", e => window.__errors.push(String(e.message || e)));
window.addEventListener("load", () => {
  const imgs = [...document.images];
  const broken = imgs.filter(i => !i.complete || i.naturalWidth === 0).map(i => i.getAttribute("src"));
  const s = document.getElementById("selfcheck");
  s.dataset.images = imgs.length;
  s.dataset.broken = broken.length;
  s.dataset.errors = window.__errors.length;
  s.textContent = "self-check: " + imgs.length + " images, " + broken.length + " broken"
    + (broken.length ? " (" + broken.join(", ") + ")" : "") + ", " + window.__errors.length
    + " script errors" + (window.__errors.length ? ": " + window.__errors.join("; ") : "");
});
