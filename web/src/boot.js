// Starts the page (src/render/page/assets.rs): a page opened from file://
// can import no file, so the embedded three.js modules and the page's own
// become blob URLs, each module's imports rewritten to its dependency's URL.
(function boot() {
  window.activecalBoot = performance.now();
  const text = (id) => document.getElementById(id).textContent;
  const url = (t) => URL.createObjectURL(new Blob([t], { type: 'text/javascript' }));
  const swap = (t, from, to) => t.split(from).join(JSON.stringify(to));
  const core = url(text('three-core'));
  const three = url(swap(text('three-module'), "'./three.core.js'", core));
  const orbit = url(swap(text('three-orbit'), "'three'", three));
  const page = swap(
    swap(text('page-module'), "'three/addons/controls/OrbitControls.js'", orbit),
    "'three'",
    three,
  );
  import(url(page)).catch((e) => {
    console.error(`activecal page: ${e}`);
  });
})();
