"""The one web stack every page of vest is served by: Starlette apps under uvicorn.

The robot's pages (the live view, replays, the therapist's buttons) and the cloud service
share what is here: how every page's stream is fed from the robot's threads without holding a
thread (:mod:`.broadcast`), server-sent events with keep-alives (:mod:`.sse`), the security
headers and the loopback-or-token rule (:mod:`.guard`), the limit on request bodies
(:mod:`.body_limit`) and how a server is bound and run beside the robot
(:mod:`.serving`). Imports Starlette and uvicorn only: no robot code.
"""
