"""The names in a run folder: its files, the statuses a run ends in, and the files that mark a folder as a run
folder. :mod:`ropesim.io.runfolder` writes and reads them; :mod:`ropesim.io.guard` recognises them."""

FORMAT = "ropesim run folder 2"
MANIFEST, LOCK, CHECKPOINT, STATE = "manifest.json", ".lock", "checkpoint", "state.npz"
TRAJECTORY, SCENE, SUMMARY, LEDGER = "trajectory.npz", "scene.toml", "summary.json", "ledger.npz"
COMPLETED, BLEW_UP, INTERRUPTED, INCOMPLETE = "completed", "blew_up", "interrupted", "incomplete"
FINISHED = (COMPLETED, BLEW_UP)
RUN_MARKERS = (MANIFEST, SCENE, TRAJECTORY, SUMMARY, CHECKPOINT, LEDGER)
