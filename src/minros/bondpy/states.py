"""The bond state machine as data: (state, event) -> (next state, actions).

Events: the sister's heartbeat (SisterAlive), its dead heartbeat (SisterDead), the three
timeouts and our own Die. Actions are the Bond's methods of the same name. A pair missing
from the table leaves the state as it is and does nothing.
"""

from __future__ import annotations

from typing import Dict, Tuple

WAITING = "SM.WaitingForSister"
ALIVE = "SM.Alive"
AWAIT_SISTER_DEATH = "SM.AwaitSisterDeath"
DEAD = "SM.Dead"

TRANSITIONS: Dict[Tuple[str, str], Tuple[str, Tuple[str, ...]]] = {
    (WAITING, "ConnectTimeout"): (DEAD, ("Death",)),
    (WAITING, "Die"): (DEAD, ("Death",)),
    (WAITING, "SisterAlive"): (ALIVE, ("Connected",)),
    (WAITING, "SisterDead"): (DEAD, ("Connected", "SisterDied", "Death")),
    (ALIVE, "Die"): (AWAIT_SISTER_DEATH, ("StartDying",)),
    (ALIVE, "HeartbeatTimeout"): (DEAD, ("Death",)),
    (ALIVE, "SisterAlive"): (ALIVE, ("Heartbeat",)),
    (ALIVE, "SisterDead"): (DEAD, ("SisterDied", "Death")),
    (AWAIT_SISTER_DEATH, "DisconnectTimeout"): (DEAD, ("Death",)),
    (AWAIT_SISTER_DEATH, "SisterDead"): (DEAD, ("Death",)),
}


#: the pairs that stay in their state doing nothing (ROS's BondSM.sm names them); every other
#: pair missing from TRANSITIONS is one the machine does not define (SMC raises for those,
#: and Bond, which never makes them, ignores them)
STAYS = frozenset({(AWAIT_SISTER_DEATH, "Die"), (AWAIT_SISTER_DEATH, "HeartbeatTimeout"),
                   (AWAIT_SISTER_DEATH, "SisterAlive")}
                  | {(DEAD, event) for event in ("ConnectTimeout", "Die", "DisconnectTimeout",
                                                 "HeartbeatTimeout", "SisterAlive", "SisterDead")})
EVENTS = ("ConnectTimeout", "Die", "DisconnectTimeout", "HeartbeatTimeout", "SisterAlive",
          "SisterDead")


def step(state: str, event: str) -> Tuple[str, Tuple[str, ...]]:
    return TRANSITIONS.get((state, event), (state, ()))
