"""Other tools' formats: BehaviorTree.CPP's XML (Groot2), its FileLogger2 logs, MCAP."""
