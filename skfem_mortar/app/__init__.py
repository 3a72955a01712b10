"""The application layer: building and running the reference scenes (:mod:`.runner`), the
command line (:mod:`.cli`), the demo, parameter studies and their reports (:mod:`.demo`,
:mod:`.study`, :mod:`.study_report`) and the benchmarks (:mod:`.bench`). Nothing below imports
from it.
"""
