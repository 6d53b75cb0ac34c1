"""Drawing softarm: matplotlib helpers (:mod:`.arm`, :mod:`.gripper`) and the rerun view
(the optional ``viz`` extra, imported only when used): :mod:`.sim_view` streams a
simulated harvest live, :mod:`.replay` turns a run log into a recording, both through
:mod:`.records`, :mod:`.scene` and :mod:`.layout`; :mod:`.rerun_sdk` opens and closes
the recordings."""
