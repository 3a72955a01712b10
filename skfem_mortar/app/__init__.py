"""The application layer: building and running the reference scenes (:mod:`.runner`), the
command line (:mod:`.cli`), the demo (:mod:`.demo`), parameter studies (:mod:`.study`: the
run; :mod:`.study_plan`, :mod:`.study_rows`, :mod:`.study_measures`) and their reports
(:mod:`.study_report`) and the benchmarks (:mod:`.bench`). Nothing below imports from it.
"""
