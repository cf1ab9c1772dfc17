"""The small instance of every registered environment, from its facts
(:attr:`iceenvs.facts.EnvFacts.small`): the one table the tests share."""
from iceenvs import ENV_IDS
from iceenvs.facts import env_facts

#: env id → ``gymnasium.make`` keywords of its small instance
SMALL = {env_id: dict(env_facts(env_id).small) for env_id in ENV_IDS}
