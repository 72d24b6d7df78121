# The grading example's three controllers: each is grading_pid.c built with its own gains (the
# macros it reads; the tuned PID is its defaults). Included by this folder's CMakeLists.txt
# (built against an installed hiltwin) and by tests/controllers (built inside hiltwin's build
# for the campaign's tests), so both build the same three libraries.
set(HILTWIN_GRADING_CONTROLLERS tuned_pid sluggish_p unstable_pi)
set(HILTWIN_GRADING_tuned_pid_DEFINES "")
set(HILTWIN_GRADING_sluggish_p_DEFINES GRADING_KP=3.0 GRADING_KI=0.0 GRADING_KD=0.0)
set(HILTWIN_GRADING_unstable_pi_DEFINES GRADING_KP=100.0 GRADING_KI=20000.0 GRADING_KD=0.0)
