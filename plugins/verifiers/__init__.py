"""Built-in verifiers: stages that rescore or reject the candidates of any detector."""
