// A script of the site loaded once, when the page first needs it (kit-report.js, kit-draco.js):
// a first visit does not wait for it. Resolves to what the script sets on window as `global`;
// after a failed load the next call tries again.
const loading = new Map();

export function lazyScript(src, global) {
  if (!loading.has(src)) {
    loading.set(src, new Promise((resolve, reject) => {
      const script = Object.assign(document.createElement("script"), {src});
      script.onload = () => {
        if (window[global]) resolve(window[global]);
        else reject(new Error(`${src} set no ${global}`));
      };
      script.onerror = () => {
        loading.delete(src);
        reject(new Error(`${src} could not be loaded`));
      };
      document.head.append(script);
    }));
  }
  return loading.get(src);
}
