// The page-wide inputs of the editor: the material picker (asks before
// discarding unsaved edits), the n, k upload, leaving the page with unsaved
// edits (beforeunload), and Ctrl+Z / Ctrl+Shift+Z (Ctrl+Y). Each calls a
// hook; none changes the state itself:
//   unsaved() -> bool, picked() -> the picker value open,
//   onPick(value) -> Promise, onUpload(file), onOpenFile(file) (a pack or an export), onUndo(), onRedo().

const $ = (id) => document.getElementById(id);

/** Whether the page may leave the material open: no unsaved edits (`dirty` false), or the artist says so. */
export const mayDiscard = (dirty) => !dirty || window.confirm("Discard the unsaved edits of this material?");

export function bindPageInputs(hooks) {
  $("material").addEventListener("change", (event) => {
    const value = event.target.value;
    if (!mayDiscard(hooks.unsaved())) {
      event.target.value = hooks.picked();
      return;
    }
    hooks.onPick(value);
  });
  $("upload").addEventListener("change", (event) => {
    const file = event.target.files[0];
    if (file) hooks.onUpload(file);
  });
  $("open-file").addEventListener("change", (event) => {
    const file = event.target.files[0];
    event.target.value = ""; // the same file can be opened again
    if (file && mayDiscard(hooks.unsaved())) hooks.onOpenFile(file);
  });
  window.addEventListener("beforeunload", (event) => {
    if (!hooks.unsaved()) return;
    event.preventDefault();
    event.returnValue = "";
  });
  document.addEventListener("keydown", (event) => {
    if (!(event.ctrlKey || event.metaKey) || event.target.matches("input[type=text], input[type=password]")) return;
    const k = event.key.toLowerCase();
    if (k === "z" && !event.shiftKey) { event.preventDefault(); hooks.onUndo(); }
    if ((k === "z" && event.shiftKey) || k === "y") { event.preventDefault(); hooks.onRedo(); }
  });
}
